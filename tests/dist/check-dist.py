#!/usr/bin/env python3
"""Compares a distributed run with a central one, from their traces.

check-dist.py CENTRAL.csv HLC.csv [--llc L=FILE ...] [--vmax L=MM_S ...]
              [--period S] [--dev-max MM] [--contour-pct P] [--contour-floor MM]
              [--no-compare]

Checks (each prints one line; exit 1 if one fails):
 - no jump: in the HLC's trace and every LLC's, no commanded step between two
   periods larger than the axis's MAX_VELOCITY * period (+ 1 um) (the plant's
   largest step is printed beside it);
 - the commanded path the LLCs played (their traces merged by period) lies
   within --dev-max of the central run's commanded path (its polyline),
   leaving out the periods up to 50 after one an LLC's loop woke too late
   to play (gap 3: the axis held, then caught up within MAX_VELOCITY);
 - the contour error on the plant (the LLCs' actual positions against their
   commanded path) is within --contour-pct of the central run's (same
   measure on the central trace's cmd/act), or --contour-floor, whichever is
   larger, over the periods at least 50 periods after a bridged or held one,
   or one whose next setpoint was late for the servo's feed-forward (the LLC
   trace's gap column: any but 0), and 150 after a left-out one or a run of
   3 or more held ones (the saturated drive's catch-up), which must be at
   least a quarter of them.
"""
import argparse
import csv
import math
import sys


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    # a writer killed mid-row (hlc-killed) leaves its last row cut short
    if rows and (None in rows[-1].values() or None in rows[-1]):
        rows.pop()
    return rows


def seg_dist(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    L = sum(x * x for x in ab)
    t = 0.0 if L == 0 else max(0.0, min(1.0, sum(ap[i] * ab[i] for i in range(3)) / L))
    return math.dist(p, [a[i] + t * ab[i] for i in range(3)])


def path_dev(points, path):
    """Largest distance of points (in order) to the polyline path."""
    # a dwell or a pause repeats one point for many periods: as one point,
    # so that the search window ahead of the last match spans the path
    path = [p for i, p in enumerate(path) if i == 0 or p != path[i - 1]]
    # A path that goes back over itself (Z up, then down the same line) puts
    # a point at the same distance from both passes: the later one wins, so
    # the match moves on with the motion instead of staying on the first
    # pass until the window no longer reaches the rest of the path.
    worst, j = 0.0, 0
    n = len(path)
    for p in points:
        # most points lie on the path a segment or two on (1 nm): the wide
        # search only for the others
        near = [k for k in range(j, min(n - 1, j + 6)) if seg_dist(p, path[k], path[k + 1]) <= 1e-6]
        if near:
            j = near[-1]
            continue
        best, bj = math.inf, j
        for k in range(max(0, j - 50), min(n - 1, j + 300)):
            d = seg_dist(p, path[k], path[k + 1])
            if d < best - 1e-9 or (d <= best + 1e-9 and k > bj):
                best, bj = min(d, best), k
        j = bj
        worst = max(worst, best)
    return worst


def contour(cmd, act):
    """Max and mean distance of each actual point to the commanded polyline
    near it (the tool's deviation from the path, whatever the lag along it)."""
    worst, tot = 0.0, 0.0
    for i, p in enumerate(act):
        if p is None:
            continue
        lo, hi = max(0, i - 20), min(len(cmd) - 1, i + 5)
        d = min(seg_dist(p, cmd[k], cmd[k + 1]) for k in range(lo, hi)) if hi > lo else 0.0
        worst = max(worst, d)
        tot += d
    return worst, tot / max(1, len(act))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("central")
    ap.add_argument("hlc")
    ap.add_argument("--llc", action="append", default=[])
    ap.add_argument("--vmax", action="append", default=[])
    ap.add_argument("--period", type=float, default=0.001)
    ap.add_argument("--dev-max", type=float, default=0.2)
    ap.add_argument("--contour-pct", type=float, default=5.0)
    ap.add_argument("--contour-floor", type=float, default=0.0005)
    ap.add_argument("--no-compare", action="store_true")
    ap.add_argument("--cut", type=float, default=None,
                    help="compare the LLCs' periods before this many seconds of motion only")
    ap.add_argument("--played-only", action="store_true",
                    help="the path over the periods each LLC played the HLC's own setpoint "
                         "in (gap 0 or 4): one held or bridged over a late HLC is left out")
    ap.add_argument("--no-contour", action="store_true",
                    help="path and steps only (runs with losses: the servo sees the gaps)")
    a = ap.parse_args()
    vmax = {k: float(v) for k, v in (s.split("=") for s in a.vmax)}
    llc = {k: read(v) for k, v in (s.split("=") for s in a.llc)}
    failed = 0

    hlc = read(a.hlc)
    for ax in "xyz":
        lim = vmax.get(ax.upper(), 200.0) * a.period + 1e-3
        c = [float(r[ax + "_cmd"]) for r in hlc]
        step = max((abs(c[i + 1] - c[i]) for i in range(len(c) - 1)), default=0.0)
        ok = step <= lim
        failed += not ok
        print(f"{'ok' if ok else 'FAIL'}: HLC {ax.upper()}: largest step {step * 1000:.1f} um"
              f" (limit {lim * 1000:.1f} um)")
    for ax, rows in sorted(llc.items()):
        lim = vmax.get(ax, 200.0) * a.period + 1e-3
        c = [float(r["cmd"]) for r in rows]
        x = [float(r["act"]) for r in rows]
        step = max((abs(c[i + 1] - c[i]) for i in range(len(c) - 1)), default=0.0)
        astep = max((abs(x[i + 1] - x[i]) for i in range(len(x) - 1)), default=0.0)
        ok = step <= lim
        failed += not ok
        print(f"{'ok' if ok else 'FAIL'}: LLC {ax}: largest step commanded {step * 1000:.1f} um"
              f" (limit {lim * 1000:.1f} um); of the plant {astep * 1000:.1f} um")
    if a.no_compare or len(llc) < 3:
        return failed and 1

    central = read(a.central)
    ccmd = [[float(r[k + "_cmd"]) for k in "xyz"] for r in central]
    cact = [[float(r[k + "_act"]) for k in "xyz"] for r in central]
    # the LLCs' periods, merged: every axis's row for the same HLC period
    by = [{round(float(r["slot"]), 6): r for r in llc[k]} for k in "XYZ"]
    slots = sorted(s for s in set(by[0]) & set(by[1]) & set(by[2])
                   if a.cut is None or s < a.cut)
    dcmd = [[float(by[i][s]["cmd"]) for i in range(3)] for s in slots]
    dact = [[float(by[i][s]["act"]) for i in range(3)] for s in slots]
    # a period bridged or held (a loss, or the HLC's loop late by more than
    # the LLCs' buffer) disturbs the servo for a while: the comparison with
    # the central run takes the periods at least SETTLE after the last one
    SETTLE = 50   # 5 time constants of the simulated servo loop (~100 rad/s)
    # A left-out period (gap 3) is caught up at once by the commanded path,
    # but the simulated drive saturates at 3 times the axis's acceleration
    # and velocity, as an amplifier does (src/backend/sim_drive.h): after a
    # stall of a dozen periods its catch-up takes up to 100 periods, then
    # SETTLE more.
    SETTLE_LEFT_OUT = 150
    # A run of held periods in motion (the HLC's loop stalled longer than
    # the LLCs' buffer) stops the setpoints as a left-out run does: the
    # same catch-up of the saturated drive follows it
    LONG_HOLD = 3
    last_gap, last_late, last_hold, clean, on_time = -10 ** 9, -10 ** 9, -10 ** 9, [], []
    left_out = held_run = 0
    for i, s in enumerate(slots):
        gaps = [by[k][s].get("gap", "0") for k in range(3)]
        if any(g != "0" for g in gaps):
            last_gap = i
        if "3" in gaps:
            last_late = i
            left_out += 1
        held_run = held_run + 1 if "2" in gaps else 0
        if held_run >= LONG_HOLD:
            last_hold = i
        clean.append(i - last_gap >= SETTLE and i - last_late >= SETTLE_LEFT_OUT and
                     i - last_hold >= SETTLE_LEFT_OUT)
        on_time.append(i - last_late >= SETTLE and
                       not (a.played_only and any(g not in ("0", "4") for g in gaps)))
    dev = path_dev([p for p, c in zip(dcmd, on_time) if c], ccmd)
    ok = dev <= a.dev_max
    failed += not ok
    print(f"{'ok' if ok else 'FAIL'}: commanded path (LLCs) vs central: max deviation"
          f" {dev * 1000:.3f} um over {sum(on_time)} of {len(slots)} periods"
          f" (limit {a.dev_max * 1000:.1f} um; {left_out} left out by a late loop)")
    hdev = path_dev([[float(r[k + "_cmd"]) for k in "xyz"] for r in hlc], ccmd)
    if a.played_only:
        ok = hdev <= a.dev_max
        failed += not ok
    print(f"{'info' if not a.played_only else 'ok' if ok else 'FAIL'}: commanded path (HLC) vs "
          f"central: max deviation {hdev * 1000:.3f} um")
    if a.no_contour:
        return failed and 1
    cmax, cavg = contour(ccmd, cact)
    dmax, davg = contour(dcmd, dact)
    kmax, _ = contour(dcmd, [p if c else None for p, c in zip(dact, clean)])
    lim = max(cmax * (1 + a.contour_pct / 100), cmax + a.contour_floor)
    ok = kmax <= lim
    failed += not ok
    print(f"{'ok' if ok else 'FAIL'}: contour error on the plant: max {kmax * 1000:.3f} um"
          f" over the {sum(clean)} of {len(slots)} periods clear of a gap (all: max"
          f" {dmax * 1000:.3f} um, avg {davg * 1000:.3f} um); central max {cmax * 1000:.3f} um,"
          f" avg {cavg * 1000:.3f} um (limit {lim * 1000:.3f} um)")
    # on a loaded host the HLC's loop is late now and then; a quarter of the
    # run still makes the comparison mean something
    ok = sum(clean) >= len(slots) // 4
    failed += not ok
    print(f"{'ok' if ok else 'FAIL'}: at least a quarter of the periods clear of a gap")
    return failed and 1


if __name__ == "__main__":
    sys.exit(main())
