#!/usr/bin/python3
"""Draws a `cnc-run run --trace` CSV as one PNG a machinist can read.

usage: plot-trace.py TRACE.csv OUT.png [LATENCY.csv] [--title TEXT]

TRACE.csv   the per-cycle trace (t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion,
            then the machine functions spindle_rpm,spindle_deg,mist,flood,dout,tool,wait;
            motion: 0 rapid G0, 1 feed G1, 2 arc G2/G3; traces without it
            are drawn as feeds); then a_cmd,a_act,... for each axis the
            machine has beyond X Y Z)
LATENCY.csv optional sidecar written by `cnc-run run --plot`: the position
            loop's wake-up latency histogram, one row per non-empty 1 us bin,
            header "latency_us,cycles" (the last row may be ">=1000" for the
            overflow bin).

Panels: commanded vs actual XY toolpath (equal aspect; rapids dashed grey,
feeds solid blue, arcs solid purple), path velocity (rapids grey) and
acceleration over time, loop-latency histogram, spindle speed, rotary axes
A B C over time (degrees) when the machine has them. Needs python3-matplotlib.
"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_trace(path):
    cols = {}
    with open(path, newline="") as f:
        rd = csv.reader(f)
        head = next(rd)
        for h in head:
            cols[h] = []
        for row in rd:
            if len(row) != len(head):
                continue
            for h, v in zip(head, row):
                cols[h].append(float(v))
    for need in ("t", "x_cmd", "y_cmd", "x_act", "y_act", "v"):
        if need not in cols:
            sys.exit("plot-trace: %s has no column %r" % (path, need))
    return cols


def read_latency(path):
    bins, counts, overflow = [], [], 0
    with open(path, newline="") as f:
        rd = csv.reader(f)
        next(rd, None)
        for row in rd:
            if len(row) != 2:
                continue
            if row[0].startswith(">="):
                overflow = int(row[1])
            else:
                bins.append(int(row[0]))
                counts.append(int(row[1]))
    return bins, counts, overflow


def thin(xs, step):
    return xs[::step] if step > 1 else xs


# motion column -> how the commanded path is drawn
STYLES = {0: dict(color="0.4", lw=1.0, ls=(0, (5, 3)), label="rapid (G0)"),
          1: dict(color="tab:blue", lw=1.6, ls="-", label="feed (G1)"),
          2: dict(color="tab:purple", lw=1.6, ls="-", label="arc (G2/G3)")}


def runs_by_motion(xs, ys, motion, step):
    """Per motion kind, the points of its stretches with NaN between stretches,
    each stretch starting at the previous one's last point (no gaps)."""
    out = {k: ([], []) for k in STYLES}
    nan = float("nan")
    n = len(xs)
    i = 0
    while i < n:
        k = int(motion[i]) if int(motion[i]) in STYLES else 1
        j = i
        while j + 1 < n and int(motion[j + 1]) == int(motion[i]):
            j += 1
        lo = max(0, i - 1)
        idx = list(range(lo, j + 1, step))
        if idx[-1] != j:
            idx.append(j)
        if j + 1 < n:
            idx.append(j + 1)
        px, py = out[k]
        px.extend(xs[m] for m in idx)
        py.extend(ys[m] for m in idx)
        px.append(nan)
        py.append(nan)
        i = j + 1
    return out


def path_accel(t, v):
    """Central differences over a window wide enough to hide sample noise."""
    n = len(t)
    a = [0.0] * n
    for i in range(n):
        lo, hi = max(0, i - 2), min(n - 1, i + 2)
        dt = t[hi] - t[lo]
        a[i] = (v[hi] - v[lo]) / dt if dt > 0 else 0.0
    return a


def plot(trace, out, lat_path, title):
    c = read_trace(trace)
    t = c["t"]
    if not t:
        sys.exit("plot-trace: %s has no rows" % trace)
    step = max(1, len(t) // 20000)   # keep the PNG readable and the script fast
    fig = plt.figure(figsize=(14, 10), dpi=100)
    # traces with the machine functions (spindle_rpm and after) get a spindle panel
    spindle = c.get("spindle_rpm")
    rotary = [n for n in "abc" if n + "_cmd" in c]
    gs = fig.add_gridspec(3 + bool(spindle) + bool(rotary), 2, width_ratios=[1.25, 1], hspace=0.55,
                          wspace=0.22)
    fig.suptitle(title, fontsize=13)

    motion = c.get("motion") or [1.0] * len(t)
    ax = fig.add_subplot(gs[:, 0])
    runs = runs_by_motion(c["x_cmd"], c["y_cmd"], motion, step)
    for k in (1, 2, 0):
        if runs[k][0]:
            ax.plot(runs[k][0], runs[k][1], zorder=3 if k == 0 else 2, **STYLES[k])
    # underneath: where it shows, the axes did not follow the command
    ax.plot(thin(c["x_act"], step), thin(c["y_act"], step), color="tab:red", lw=0.6,
            alpha=0.35, zorder=1, label="actual (simulated axes)")
    ferr = max(((xc - xa) ** 2 + (yc - ya) ** 2) ** 0.5 for xc, yc, xa, ya in
               zip(c["x_cmd"], c["y_cmd"], c["x_act"], c["y_act"]))
    ax.plot(c["x_cmd"][0], c["y_cmd"][0], "o", color="tab:green", ms=7, zorder=4, label="start")
    ax.plot(c["x_cmd"][-1], c["y_cmd"][-1], "s", color="black", ms=6, zorder=4, label="end")
    ax.text(0.02, 0.02, "max XY following error %.4f mm\n(actual lies on commanded at this scale)"
            % ferr if ferr < 0.05 else "max XY following error %.4f mm" % ferr,
            transform=ax.transAxes, fontsize=9, va="bottom",
            bbox=dict(facecolor="white", alpha=0.8, edgecolor="none"))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("X [mm]")
    ax.set_ylabel("Y [mm]")
    ax.set_title("XY toolpath (machine coordinates)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=9)

    v = c["v"]
    vmin = [x * 60.0 for x in v]
    axv = fig.add_subplot(gs[0, 1])
    vruns = runs_by_motion(t, vmin, motion, step)
    for k, color, label in ((1, "tab:green", "feed"), (2, "tab:green", None),
                            (0, "0.55", "rapid")):
        if vruns[k][0]:
            axv.plot(vruns[k][0], vruns[k][1], color=color, lw=0.9, label=label)
    if vruns[0][0]:
        axv.legend(loc="upper right", fontsize=8)
    axv.set_ylabel("feed [mm/min]")
    axv.set_title("path velocity")
    axv.grid(True, alpha=0.3)

    a = path_accel(t, v)
    axa = fig.add_subplot(gs[1, 1], sharex=axv)
    axa.plot(thin(t, step), thin(a, step), color="tab:brown", lw=0.7)
    axa.set_ylabel("accel [mm/s²]")
    axa.set_xlabel("time [s]")
    axa.set_title("path acceleration (dv/dt)")
    axa.grid(True, alpha=0.3)

    axh = fig.add_subplot(gs[2, 1])
    axh.set_title("position-loop wake-up latency")
    if lat_path:
        bins, counts, overflow = read_latency(lat_path)
        if bins:
            axh.bar(bins, counts, width=1.0, color="tab:orange", align="edge")
            if max(counts) > 100 * max(1, min(counts)):
                axh.set_yscale("log")
            hi = max(bins) + 1
            axh.set_xlim(0, max(10, hi + 1))
        total = sum(counts) + overflow
        note = "%d cycles, max bin %d us" % (total, max(bins) if bins else 0)
        if overflow:
            note += ", %d >= 1000 us" % overflow
        axh.text(0.98, 0.92, note, transform=axh.transAxes, ha="right", va="top",
                 fontsize=9)
        axh.set_xlabel("latency [us] (1 us bins)")
        axh.set_ylabel("cycles")
    else:
        axh.text(0.5, 0.5, "no latency histogram given", ha="center", va="center",
                 transform=axh.transAxes)
        axh.set_axis_off()
    if spindle:
        axs = fig.add_subplot(gs[3, 1], sharex=axv)
        axs.plot(thin(t, step), thin(spindle, step), color="tab:purple", lw=0.9,
                 label="spindle (actual)")
        for name, color in (("flood", "tab:blue"), ("mist", "tab:cyan")):
            on = c.get(name)
            if on and max(on) > 0:
                top = max(1.0, max(abs(x) for x in spindle))
                axs.fill_between(thin(t, step), 0, [x * top for x in thin(on, step)],
                                 color=color, alpha=0.12, step="post", label=name)
        axs.set_ylabel("spindle [rpm]")
        axs.set_xlabel("time [s]")
        axs.set_title("spindle speed (M4 negative), coolant shaded")
        axs.grid(True, alpha=0.3)
        axs.legend(loc="upper right", fontsize=8)
    if rotary:
        axr = fig.add_subplot(gs[3 + bool(spindle), 1], sharex=axv)
        for n in rotary:
            axr.plot(thin(t, step), thin(c[n + "_cmd"], step), lw=0.9, label=n.upper())
        axr.set_ylabel("angle [deg]")
        axr.set_xlabel("time [s]")
        axr.set_title("rotary axes (commanded; a wrapped axis counts on past 360)")
        axr.grid(True, alpha=0.3)
        axr.legend(loc="upper right", fontsize=8)
    fig.savefig(out)
    plt.close(fig)


def main(argv):
    title = None
    if "--title" in argv:
        i = argv.index("--title")
        if i + 1 >= len(argv):
            sys.exit(__doc__)
        title = argv[i + 1]
        del argv[i:i + 2]
    if len(argv) not in (3, 4):
        sys.exit(__doc__)
    plot(argv[1], argv[2], argv[3] if len(argv) == 4 else None, title or argv[1])


if __name__ == "__main__":
    main(sys.argv)
