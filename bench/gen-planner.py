#!/usr/bin/python3
"""Writes one of the planner comparison programs (bench/planner-vs-lcnc):
deterministic for a kind and a block count, every one G21 G90 G64 P0.01 Q0 F3000
(Q0: no line merging, so both planners see every block), starting at 0,0,0.

kinds: sharp   CAM-like 1 mm moves with small arcs and sharp turns (60-150 deg)
       arcs    chains of tangent arcs (G2/G3 alternating, radius 1-10 mm)
       tiny    tiny CAM segments (0.02-0.2 mm) along a smooth curving path
       lines   long lines (20-120 mm) joined at corners
       helix   helices: full turns of G2 with a Z feed, radius 2-20 mm
       square  squares of 2-20 mm side, 90 deg corners
       walk    random walk: any direction, 0.2-5 mm steps
       stairs  steps along X and Y in turn, 0.5-5 mm, every corner 90 deg
               between axis-aligned lines (where tools/planner-bound.py's
               per-axis floor applies)
       cam     a CAM contour: 1 mm lines turning up to 15 deg each, Z
               following a surface, and a tangent G2/G3 (radius 2-10 mm)
               every 10th block
usage: gen-planner.py KIND [BLOCKS]"""
import math
import random
import sys

HEAD = "G21 G90 G17 G94 G64 P0.01 Q0\nG1 F3000\n"
TAIL = "M2\n"
LIM = 200.0  # stay well inside X/Y +-500


def fmt(x, y, z=None):
    s = "X%.4f Y%.4f" % (x, y)
    return s + (" Z%.4f" % z if z is not None else "")


def tangent_arc(x, y, h, rad, turn, cw):
    """A G2 (cw) or G3 of radius rad leaving (x, y) along heading h and
    turning by turn: its block, where it ends and its heading there."""
    nx, ny = (math.sin(h), -math.cos(h)) if cw else (-math.sin(h), math.cos(h))
    cx, cy = x + rad * nx, y + rad * ny
    a0 = math.atan2(y - cy, x - cx)
    a1 = a0 - turn if cw else a0 + turn
    ex, ey = cx + rad * math.cos(a1), cy + rad * math.sin(a1)
    block = "%s %s I%.4f J%.4f" % ("G2" if cw else "G3", fmt(ex, ey), cx - x, cy - y)
    return block, ex, ey, h - turn if cw else h + turn


def sharp(r, n):
    out, x, y, h = [], 0.0, 0.0, 0.0
    while len(out) < n:
        if len(out) % 7 == 6:
            # a small arc leaving tangentially, turning by up to 90 deg
            rad = r.uniform(0.5, 2.0)
            cw = r.random() < 0.5
            block, x, y, h = tangent_arc(x, y, h, rad, r.uniform(0.3, 1.5), cw)
            out.append(block)
        else:
            h += r.choice([-1, 1]) * math.radians(r.uniform(60, 150))
            x += math.cos(h)
            y += math.sin(h)
            out.append("G1 " + fmt(x, y))
        if abs(x) > LIM or abs(y) > LIM:
            h = math.atan2(-y, -x)
    return out


def arcs(r, n):
    out, x, y, h, cw = [], 0.0, 0.0, 0.0, True
    for _ in range(n):
        rad = r.uniform(1.0, 10.0)
        turn = r.uniform(0.3, 2.5)
        nx, ny = (math.sin(h), -math.cos(h)) if cw else (-math.sin(h), math.cos(h))
        cx, cy = x + rad * nx, y + rad * ny
        a0 = math.atan2(y - cy, x - cx)
        a1 = a0 - turn if cw else a0 + turn
        ex, ey = cx + rad * math.cos(a1), cy + rad * math.sin(a1)
        out.append("%s %s I%.4f J%.4f" % ("G2" if cw else "G3", fmt(ex, ey), cx - x, cy - y))
        x, y = ex, ey
        h += -turn if cw else turn
        cw = not cw
    return out


def tiny(r, n):
    out, x, y, z, h, dh = [], 0.0, 0.0, 0.0, 0.0, 0.0
    for i in range(n):
        dh = max(-0.3, min(0.3, dh + r.uniform(-0.05, 0.05)))
        h += dh
        step = r.uniform(0.02, 0.2)
        x += step * math.cos(h)
        y += step * math.sin(h)
        z = -0.5 - 0.3 * math.sin(i * 0.05)
        out.append("G1 " + fmt(x, y, z))
    return out


def lines(r, n):
    out, x, y = [], 0.0, 0.0
    for _ in range(n):
        h = r.uniform(0, 2 * math.pi)
        d = r.uniform(20, 120)
        x, y = x + d * math.cos(h), y + d * math.sin(h)
        if abs(x) > LIM or abs(y) > LIM:
            x, y = x * 0.5, y * 0.5
        out.append("G1 " + fmt(x, y, r.uniform(-5, 0)))
    return out


def helix(r, n):
    out, z = [], 0.0
    x = y = 0.0
    for _ in range(n):
        rad = r.uniform(2, 20)
        # centre to the left; a full turn ends where it started, lower in Z
        z -= r.uniform(0.2, 3.0)
        out.append("G2 %s I%.4f J0 P1" % (fmt(x, y, z), rad))
        # step sideways to the next helix's start
        x += r.uniform(-3, 3)
        y += r.uniform(-3, 3)
        out.append("G1 " + fmt(x, y, z))
    return out[:n]


def square(r, n):
    out, x0, y0 = [], 0.0, 0.0
    while len(out) < n:
        s = r.uniform(2, 20)
        for dx, dy in ((s, 0), (s, s), (0, s), (0, 0)):
            out.append("G1 " + fmt(x0 + dx, y0 + dy))
        x0 += r.uniform(-1, 1)
        y0 += r.uniform(-1, 1)
    return out[:n]


def walk(r, n):
    out, x, y = [], 0.0, 0.0
    for _ in range(n):
        h = r.uniform(0, 2 * math.pi)
        d = r.uniform(0.2, 5)
        x, y = x + d * math.cos(h), y + d * math.sin(h)
        if abs(x) > LIM or abs(y) > LIM:
            x, y = 0.0, 0.0
        out.append("G1 " + fmt(x, y))
    return out


def stairs(r, n):
    out, x, y = [], 0.0, 0.0
    sx, sy = 1, 1
    for i in range(n):
        d = r.uniform(0.5, 5)
        if i % 2 == 0:
            if abs(x + sx * d) > LIM:
                sx = -sx
            x += sx * d
        else:
            if abs(y + sy * d) > LIM:
                sy = -sy
            y += sy * d
        out.append("G1 " + fmt(x, y))
    return out


def cam(r, n):
    out, x, y, h = [], 0.0, 0.0, 0.0
    for i in range(n):
        if i % 10 == 9:
            rad = r.uniform(2, 10)
            turn = r.uniform(0.1, 0.6)
            block, x, y, h = tangent_arc(x, y, h, rad, turn, r.random() < 0.5)
            out.append(block)
        else:
            h += math.radians(r.uniform(-15, 15))
            if abs(x) > LIM or abs(y) > LIM:
                h = math.atan2(-y, -x)
            x += math.cos(h)
            y += math.sin(h)
            out.append("G1 " + fmt(x, y, -0.5 - 0.2 * math.sin(i * 0.05)))
    return out


KINDS = {"sharp": (sharp, 300), "arcs": (arcs, 100), "tiny": (tiny, 1000),
         "lines": (lines, 15), "helix": (helix, 12), "square": (square, 60),
         "walk": (walk, 150), "stairs": (stairs, 100), "cam": (cam, 300)}


def main():
    if len(sys.argv) < 2 or sys.argv[1] not in KINDS:
        sys.stderr.write(__doc__)
        sys.exit(1)
    fn, n = KINDS[sys.argv[1]]
    if len(sys.argv) > 2:
        n = int(sys.argv[2])
    r = random.Random(sys.argv[1])
    sys.stdout.write(HEAD + "\n".join(fn(r, n)) + "\n" + TAIL)


if __name__ == "__main__":
    main()
