#!/usr/bin/env python3
"""Accuracy figures of a run from its trace, as the distributed-NCK paper's Tables III-IV take them:
ISO 230-6 diagonal positioning (the ISO 230-2 statistics along a diagonal) and
ISO 10791-7 contour features, from the feedback signal (the trace's actual
positions), which ISO 230-4 Annex D permits in place of an interferometer.

  diagonal: ncprograms/iso230-6-diagonal.ngc. Every G4 dwell is a measurement:
    the actual position at its last sample, against the commanded target, along
    the diagonal. Targets are told apart by where they lie, the direction of
    approach by the commanded position before the dwell. Per target j and
    direction: mean deviation x_j and sample standard deviation s_j over the
    runs; per the diagonal: repeatability R = max_j max(4 s_up, 4 s_down,
    2 s_up + 2 s_down + |B_j|), reversal B = max_j |x_up - x_down|, systematic
    deviation E = max - min of every x_j, accuracy A = max(x + 2s) - min(x - 2s)
    over both directions; the unidirectional ones (R_up, E_up, A_up) beside.
    Straightness: the actual path's largest distance from the diagonal while
    it moves along it.
  contour: ncprograms/iso10791-7-contour.ngc. A comment "(feature line NAME)"
    or "(feature circle NAME)" on a program line names the feature its samples
    (trace column `line`) belong to. Lines: straightness as the distributed-NCK paper measures
    it (largest distances on both sides of the straight line through the
    feature's first and last actual sample, added) and angularity (the width
    of the band at the programmed angle that holds every sample). Circles:
    roundness (max - min radius about the least-squares centre), diameter
    error, and position (distance between the commanded and the actual
    least-squares centres).

All figures in micrometres.

usage: iso-accuracy.py TRACE PROGRAM [--json]
"""
import csv
import json
import math
import re
import sys


def read_trace(path):
    with open(path) as f:
        rows = csv.reader(f)
        head = next(rows)
        ix = {n: i for i, n in enumerate(head)}
        need = ["line", "x_cmd", "y_cmd", "z_cmd", "x_act", "y_act", "z_act"]
        missing = [n for n in need if n not in ix]
        if missing:
            sys.exit("iso-accuracy: %s has no column %s" % (path, ", ".join(missing)))
        out = []
        for r in rows:
            out.append((int(r[ix["line"]]),
                        (float(r[ix["x_cmd"]]), float(r[ix["y_cmd"]]), float(r[ix["z_cmd"]])),
                        (float(r[ix["x_act"]]), float(r[ix["y_act"]]), float(r[ix["z_act"]]))))
        return out


def sub(a, b):
    return tuple(p - q for p, q in zip(a, b))


def dot(a, b):
    return sum(p * q for p, q in zip(a, b))


def norm(a):
    return math.sqrt(dot(a, a))


def runs_of(samples, lines):
    """Contiguous runs of samples whose line is in lines: (line, first, last index)."""
    out, i, n = [], 0, len(samples)
    while i < n:
        if samples[i][0] in lines:
            j = i
            while j + 1 < n and samples[j + 1][0] == samples[i][0]:
                j += 1
            out.append((samples[i][0], i, j))
            i = j + 1
        else:
            i += 1
    return out


def mean_sd(v):
    m = sum(v) / len(v)
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1)) if len(v) > 1 else 0.0
    return m, sd


def diagonal(samples, prog_lines):
    dwell = {i + 1 for i, t in enumerate(prog_lines) if re.search(r"(?i)\bG0*4\b", t.split("(")[0])}
    runs = runs_of(samples, dwell)
    if len(runs) < 4:
        sys.exit("iso-accuracy: fewer than 4 dwells in the trace: not a diagonal test")
    targets = [samples[j][1] for _, _, j in runs]
    a, b = min(targets, key=lambda p: (p[0], p[1], p[2])), max(targets, key=lambda p: (p[0], p[1], p[2]))
    u = sub(b, a)
    u = tuple(c / norm(u) for c in u)
    meas = {}
    for _, i, j in runs:
        cmd, act = samples[j][1], samples[j][2]
        before = samples[max(i - 50, 0)][1]
        s = dot(sub(cmd, a), u)
        up = dot(sub(cmd, before), u) > 0
        key = round(s, 3)
        meas.setdefault(key, {True: [], False: []})[up].append(1000.0 * dot(sub(act, cmd), u))
    keys = sorted(meas)
    per, R, B, hi, lo, hi_up, lo_up, R_up, R_dn = [], 0.0, 0.0, -1e18, 1e18, -1e18, 1e18, 0.0, 0.0
    xs = []
    for k in keys:
        if not meas[k][True] or not meas[k][False]:
            sys.exit("iso-accuracy: target at %.3f mm was not approached from both directions" % k)
        mu, su = mean_sd(meas[k][True])
        md, sd = mean_sd(meas[k][False])
        Bj = mu - md
        per.append({"target_mm": k, "n_up": len(meas[k][True]), "n_down": len(meas[k][False]),
                    "mean_up": mu, "sd_up": su, "mean_down": md, "sd_down": sd, "reversal": Bj})
        R = max(R, 4 * su, 4 * sd, 2 * su + 2 * sd + abs(Bj))
        R_up, R_dn = max(R_up, 4 * su), max(R_dn, 4 * sd)
        B = max(B, abs(Bj))
        hi, lo = max(hi, mu + 2 * su, md + 2 * sd), min(lo, mu - 2 * su, md - 2 * sd)
        hi_up, lo_up = max(hi_up, mu + 2 * su), min(lo_up, mu - 2 * su)
        xs += [mu, md]
    ups = [p["mean_up"] for p in per]
    # straightness along the way: samples whose commanded point lies on the diagonal
    straight = 0.0
    for _, cmd, act in samples:
        if norm(sub(sub(cmd, a), tuple(dot(sub(cmd, a), u) * c for c in u))) < 1e-6:
            d = sub(act, a)
            straight = max(straight, norm(sub(d, tuple(dot(d, u) * c for c in u))))
    return {"kind": "diagonal", "targets": per, "runs": min(p["n_up"] for p in per),
            "repeatability": R, "repeatability_up": R_up, "repeatability_down": R_dn,
            "reversal": B, "systematic": max(xs) - min(xs), "systematic_up": max(ups) - min(ups),
            "accuracy": hi - lo, "accuracy_up": hi_up - lo_up, "straightness": 1000.0 * straight}


def fit_circle(pts):
    """Least-squares circle (Kasa): centre and radius."""
    n = len(pts)
    sx = sum(p[0] for p in pts) / n
    sy = sum(p[1] for p in pts) / n
    suu = suv = svv = suuu = svvv = suvv = svuu = 0.0
    for x, y in pts:
        u, v = x - sx, y - sy
        suu += u * u
        suv += u * v
        svv += v * v
        suuu += u * u * u
        svvv += v * v * v
        suvv += u * v * v
        svuu += v * u * u
    det = suu * svv - suv * suv
    if abs(det) < 1e-18:
        return (sx, sy), 0.0
    rhs1, rhs2 = 0.5 * (suuu + suvv), 0.5 * (svvv + svuu)
    uc = (rhs1 * svv - rhs2 * suv) / det
    vc = (suu * rhs2 - suv * rhs1) / det
    r = math.sqrt(uc * uc + vc * vc + (suu + svv) / n)
    return (sx + uc, sy + vc), r


def contour(samples, prog_lines):
    feats = {}
    for i, t in enumerate(prog_lines):
        m = re.search(r"\(\s*feature\s+(line|circle)\s+([\w.-]+)\s*\)", t, re.I)
        if m:
            feats[i + 1] = (m.group(1).lower(), m.group(2))
    if not feats:
        sys.exit("iso-accuracy: the program names no features: not a contour test")
    out = []
    for ln, (kind, name) in sorted(feats.items()):
        pts = [(c, a) for l, c, a in samples if l == ln]
        if len(pts) < 3:
            sys.exit("iso-accuracy: feature %s (line %d) has %d samples in the trace" % (name, ln, len(pts)))
        act = [(a[0], a[1]) for _, a in pts]
        cmd = [(c[0], c[1]) for c, _ in pts]
        if kind == "line":
            p0, p1 = act[0], act[-1]
            d = (p1[0] - p0[0], p1[1] - p0[1])
            L = math.hypot(*d)
            nrm = (-d[1] / L, d[0] / L)
            side = [(x - p0[0]) * nrm[0] + (y - p0[1]) * nrm[1] for x, y in act]
            c0, c1 = cmd[0], cmd[-1]
            for c in cmd:   # the programmed direction: from the first to the farthest commanded point
                if math.hypot(c[0] - c0[0], c[1] - c0[1]) > math.hypot(c1[0] - c0[0], c1[1] - c0[1]):
                    c1 = c
            e = (c1[0] - c0[0], c1[1] - c0[1])
            le = math.hypot(*e)
            ne = (-e[1] / le, e[0] / le)
            band = [(x - c0[0]) * ne[0] + (y - c0[1]) * ne[1] for x, y in act]
            out.append({"feature": name, "kind": "line",
                        "straightness": 1000.0 * (max(0.0, max(side)) - min(0.0, min(side))),
                        "angularity": 1000.0 * (max(band) - min(band))})
        else:
            cc, rc = fit_circle(cmd)
            ca, ra = fit_circle(act)
            radii = [math.hypot(x - ca[0], y - ca[1]) for x, y in act]
            out.append({"feature": name, "kind": "circle",
                        "roundness": 1000.0 * (max(radii) - min(radii)),
                        "diameter_error": 2000.0 * (ra - rc),
                        "position": 1000.0 * math.hypot(ca[0] - cc[0], ca[1] - cc[1])})
    return {"kind": "contour", "features": out}


def main():
    args = [a for a in sys.argv[1:] if a != "--json"]
    if len(args) != 2:
        sys.exit(__doc__.strip().split("\n")[-1])
    samples = read_trace(args[0])
    prog = open(args[1]).read().split("\n")
    has_features = any(re.search(r"\(\s*feature\s+(line|circle)\s", t, re.I) for t in prog)
    res = contour(samples, prog) if has_features else diagonal(samples, prog)
    if "--json" in sys.argv:
        print(json.dumps(res, indent=1))
    elif res["kind"] == "diagonal":
        print("target_mm  n  mean_up  sd_up  mean_down  sd_down  reversal   (um)")
        for p in res["targets"]:
            print("%9.3f %2d %8.3f %6.3f %10.3f %8.3f %9.3f" % (
                p["target_mm"], p["n_up"], p["mean_up"], p["sd_up"], p["mean_down"], p["sd_down"], p["reversal"]))
        for k in ("repeatability", "repeatability_up", "repeatability_down", "reversal", "systematic",
                  "systematic_up", "accuracy", "accuracy_up", "straightness"):
            print("%-20s %9.3f um" % (k, res[k]))
    else:
        for f in res["features"]:
            print("%-22s %s" % (f["feature"], "  ".join("%s %.3f um" % (k, v) for k, v in f.items()
                                                         if k not in ("feature", "kind"))))


if __name__ == "__main__":
    main()
