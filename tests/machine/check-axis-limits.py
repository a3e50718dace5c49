#!/usr/bin/python3
"""check-axis-limits.py TRACE PERIOD VMAX AMAX: the largest X, Y and Z
velocity and acceleration of a cnc-run trace's commanded samples, one servo
PERIOD (s) apart as the servo takes them (a real-clock run's skipped periods
leave a row out, not a step in the command), as shares of the limits.
Prints "vel V acc A"; exit 1 above 1.01 of either."""
import csv
import sys


def main():
    path, t, vmax, amax = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    pos = [(float(r["x_cmd"]), float(r["y_cmd"]), float(r["z_cmd"]))
           for r in csv.DictReader(open(path))]
    vel = acc = 0.0
    for k in range(1, len(pos)):
        for j in range(3):
            vel = max(vel, abs(pos[k][j] - pos[k - 1][j]) / t)
            if k + 1 < len(pos):
                acc = max(acc, abs(pos[k + 1][j] - 2 * pos[k][j] + pos[k - 1][j]) / (t * t))
    print("vel %.3f acc %.3f" % (vel / vmax, acc / amax))
    sys.exit(0 if vel / vmax <= 1.01 and acc / amax <= 1.01 else 1)


main()
