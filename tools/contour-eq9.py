#!/usr/bin/env python3
"""Contour error of a circle from a cnc-run trace, as the timing-faults paper's Eq. (9) takes
it beside ncpar's own.

Eq. (9): C is the midpoint of two successive actual positions A and B, D the
point of the ideal circle on the ray from the centre O through C; the contour
error is |CD| = | R - |OC| |. Ours: the distance of each actual point from the
commanded path (the polyline of the last 64 commanded samples, as the run's
summary measures it). Both over the periods whose commanded setpoint lies on
the arc (trace column motion = 2).

usage: contour-eq9.py TRACE [--center X,Y] [--radius R] [--series OUT.csv]
prints: eq9_max_mm eq9_mean_mm eq9_rms_mm ours_max_mm ours_mean_mm samples
"""
import argparse
import csv
import math
import sys


def seg_dist(p, a, b):
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    l2 = dx * dx + dy * dy
    f = 0.0 if l2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / l2))
    return math.hypot(ax + f * dx - p[0], ay + f * dy - p[1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("trace")
    ap.add_argument("--center", default="0,0")
    ap.add_argument("--radius", type=float, default=1000.0)
    ap.add_argument("--series", help="write t,eq9_mm,ours_mm per arc period")
    a = ap.parse_args()
    ox, oy = (float(v) for v in a.center.split(","))
    rows = []
    with open(a.trace, newline="") as f:
        for r in csv.DictReader(f):
            rows.append((float(r["t"]), float(r["x_cmd"]), float(r["y_cmd"]),
                         float(r["x_act"]), float(r["y_act"]), int(r["motion"])))
    eq9, ours, series = [], [], []
    hist = []
    prev = None
    for t, xc, yc, xa, ya, motion in rows:
        hist.append((xc, yc))
        hist = hist[-64:]
        if motion == 2 and prev is not None:
            cx, cy = (prev[0] + xa) / 2 - ox, (prev[1] + ya) / 2 - oy
            e9 = abs(a.radius - math.hypot(cx, cy))
            o = min(seg_dist((xa, ya), hist[i - 1], hist[i]) for i in range(1, len(hist))) \
                if len(hist) > 1 else math.hypot(xa - xc, ya - yc)
            eq9.append(e9)
            ours.append(o)
            series.append((t, e9, o))
        prev = (xa, ya)
    if not eq9:
        sys.exit("contour-eq9: no arc periods (motion = 2) in the trace")
    n = len(eq9)
    print("%.4f %.4f %.4f %.4f %.4f %d" % (max(eq9), sum(eq9) / n,
                                           math.sqrt(sum(e * e for e in eq9) / n),
                                           max(ours), sum(ours) / n, n))
    if a.series:
        with open(a.series, "w") as f:
            f.write("t,eq9_mm,ours_mm\n")
            for t, e9, o in series:
                f.write("%.6f,%.6f,%.6f\n" % (t, e9, o))


if __name__ == "__main__":
    main()
