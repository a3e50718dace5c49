#!/usr/bin/python3
"""Writes a CAM-like program of N blocks: G1 XYZ moves with a G2 arc every 10th
block, as a post-processor would emit for a 3-axis surfacing pass."""
import math
import sys

def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    out = sys.stdout
    w = out.write
    w("G21 G90 G17 G94\nG0 Z5.000\nG0 X0.000 Y0.000\nS12000 M3\nG1 Z-0.500 F1200\n")
    x = y = 0.0
    blocks = 5
    i = 0
    while blocks < n - 2:
        i += 1
        if i % 10 == 0:
            # a quarter-ish arc of radius 2 (centre straight ahead in +Y)
            cx, cy = x, y + 2.0
            ex, ey = cx + 2.0 * math.sin(0.7), cy - 2.0 * math.cos(0.7)
            w("G2 X%.3f Y%.3f I0.000 J2.000\n" % (ex, ey))
            x, y = ex, ey
        else:
            x = (x + 0.731) % 400.0
            y = (y + 0.217) % 300.0
            z = -0.5 - 0.25 * math.sin(i * 0.01)
            w("G1 X%.3f Y%.3f Z%.3f\n" % (x, y, z))
        blocks += 1
    w("G0 Z5.000\nM30\n")

if __name__ == "__main__":
    main()
