#!/usr/bin/env python3
"""A lower bound on the program time any planner can reach on a feed program
with per-axis limits and a G64 P tolerance: no planner that keeps every axis
within its MAX_VELOCITY and MAX_ACCELERATION, the path within P and the feed
within F can be faster. It answers "how far below LinuxCNC's time is there
room at all?" for bench/planner-vs-lcnc's programs.

Every estimate is taken on the generous side, so the bound stays a bound:
- each line runs at most at min(F, min_i vmax_i / |u_i|) and speeds up or
  slows down at most at min_i amax_i / |u_i| (exact for a straight line);
- on an arc the speed is at most sqrt(a_n R), and its speed changes at most
  at a_n, with a_n the norm of the limits of the axes its plane (or its
  helix) moves (every one of them at its limit at once, more than any
  direction can get), R the flattest turn within P of it: r + P / (1 /
  cos(sweep / 2) - 1) below half a turn (the circle of the same turn whose
  middle lies P inside the arc's, its ends on the tangents beyond the arc,
  whose segments either side lose that reach), r + P from half a turn on;
  its length is at least the inner edge's, (r - P) times the sweep (with a
  helix's rise). Taken as r itself it would not be a bound: a motion within
  P of a short arc may turn on a wider circle than the arc's. (bench/piece-lp
  once reported a piece of `sharp` from block 120, a small arc into a line
  turning the same way, done in 0.331 s and later 0.354 s, below this bound:
  its samples had been assigned to the nearest piece of path, and that
  piece's last line crosses its first, so the motion went from the first
  line to the last at the crossing and skipped 6 of the 8 blocks. Assigned
  in the path's order, the fastest motion there takes 0.401 s, the bound
  0.358 s);
- a corner from tangent u1 to u2, turning by phi, is passed at a speed no
  higher than the slowest speed of the fastest turns within P, and
  shortens the path by at most 2 P tan(phi / 2). Within P of the path
  (what our trace check and bench/piece-lp hold a motion to) the whole band
  of width 2 P is open: a motion may come in along the outer edge (P outside
  the first line), cut in to where the inner edges meet (I, P inside both
  lines, P / cos(phi / 2) from the corner) and leave along the outer edge
  of the second. A turn whose tangents are the outer edges (meeting at O,
  P / cos(phi / 2) outside the corner) may so reach 2 P / cos(phi / 2)
  from O, where one whose tangents are the lines themselves reaches P from
  the corner point: the reading this bound took until bench/piece-lp found
  two 1.5 mm lines turning 30 degrees done in 0.117 s against its 0.121
  (the motion on the outer edge, in at the corner, at 24.8 mm/s at its
  slowest against the 20.0 the bound allowed there). The turns taken:
  the circle tangent to both outer edges with its middle at I, of radius
  2 P / (1 - cos(phi / 2)), at sqrt(a_n R) (a_n the norm of the moving
  axes' limits: more than any direction gets); and the turn at a constant
  acceleration (no axis waits for another) from v u1 to v u2 between the
  outer edges: at acceleration A along w = (u2 - u1) / |u2 - u1| it takes
  T = v |u2 - u1| / A and its middle lies v T |u2 - u1| / 8 from O, so
  v^2 <= 16 A P / (|u2 - u1|^2 cos(phi / 2)), with A at most A_w =
  sum_i amax_i |w_i|; it is slowest in its middle, at v cos(phi / 2). The
  corner's speed is the larger of the circle's and that slowest: the profile
  passes the corner at the speed a motion must come down to somewhere in
  its turn, and the turn itself costs no time. Turns whose curvature or
  acceleration varies are not proved slower; a_n and A_w (every axis at its
  limit at once, which a turn rarely allows) and the free turn are the
  margin taken for them. No length of either line is asked for: a chain of
  short lines turning the same way (tiny's) may spread one turn over many
  corners. The saving: a path within P from a point of the first line to a
  point of the second crosses the bisector no further in than I, so it is
  at most 2 P tan(phi / 2) shorter than the lines (and at most twice the
  shorter line). Our parabolic blend stays below: within P of the lines
  per axis v^2 <= 8 P amax_i / (sin(phi) |u2_i - u1_i|), with its vertex moved
  out to the outer edges' meeting twice that, and sin(phi) |u2 - u1| =
  |u2 - u1|^2 cos(phi / 2) with |u2 - u1|^2 <= max_i |u2_i - u1_i| times
  sum_i |u2_i - u1_i| keeps it under the turn at A_w;
- the machine starts and ends at rest; in between the fastest profile that
  these bounds allow (forward and backward passes over the junction speeds,
  then a trapezoid on each segment).
A per-axis floor for corners between two axes (each axis rest to rest over
its side, less a saving per corner) was taken here until bench/piece-lp, the
linear program over servo samples, found motions faster than it on stairs
(6 ms on 3 blocks: an axis going on the same way need not stop) and on three
sides of a square (9 ms: the path need only be within P of either side, not
of the corner point, so one axis may start while the other is still up to P
short). It is withdrawn, not mended.

The bound printed is the larger of that one (the trapezoids) and a second,
independent one (the windows), each a lower bound, so the larger is too. The
trapezoids let every corner and every chord of a curve turn on its own and
for free, which on dense CAM chords (tiny: 0.02-0.2 mm, turning up to 0.3
rad each) leaves them at the time at feed, far below what any motion that
follows the curve can do. The windows read the turns of many blocks at once:
- the motion x(t) follows the path within P, in order (what the trapezoids'
  corner and arc arguments take too: a motion must run every block, not skip
  through a crossing): a point, the walker, goes along the path from its
  start to its end, never back, always within P of the motion; it may jump
  ahead, but never past the whole of a block nor half a turn of an arc (a
  jump starts and ends in one block or in two that follow each other: a
  blend cutting a corner is such a jump). Only "in order" makes the cross-sections below hold where the
  path comes back near itself (tiny's loops cross), which the band alone,
  as a set of points, would not. So for path points p_0 .. p_n in the path's
  order (p_0, p_n the program's ends) there are times 0 = tau_0 <= tau_1 <=
  .. <= tau_n = T with |e_k| <= E_k, e_k = x(tau_k) - p_k, e_0 = e_n = 0 (the
  motion starts and ends there): tau_k the moment the walker reaches or
  jumps past p_k, where x is within P of the walker's points A just before
  and B just after (|A - B| <= 2 P). Where the walker goes on without a jump,
  or jumps along a line, E_k = P (every point of the chord AB is within P of
  x, and p_k is on it); within an arc of radius r, P plus the height of the
  arc over a chord of 2 P; across the vertex of two blocks turning by phi,
  x is within P of both, so no further than P / cos(phi / 2) from the
  vertex (where the inner edges meet) and, by the same convexity, from the
  points between A and the vertex and the vertex and B; those lie no
  further from it than 2 P / sin(the blocks' angle, at most a right angle)
  along a line (A within 2 P of the other block). Beside an arc, which may
  bend back towards the other block, both blocks are sampled (every P / 4,
  up to half a turn of an arc) and E is P plus the most any path point
  between a jump's ends lies from their chord, a step more for the
  samples. E_k the largest of these that apply to p_k. The walker kept within P of the motion
  throughout (no jumps: a Frechet distance of P) would give E_k = P
  everywhere; a motion that cuts a sharp corner within the band is not held
  to that;
- window k, t_k = tau_k - tau_(k-1), has the mean velocity m_k = (d_k + e_k -
  e_(k-1)) / t_k, d_k = p_k - p_(k-1). Every axis within V_j and the feed
  within F: |d_k| - |e_k| - |e_(k-1)| <= F t_k, and the same per axis with V_j
  (the windows are longer than 2 P, so t_k > 0);
- for any unit vector w, w . v(t) changes at most at c_w = sum_j A_j |w_j|
  (every axis within its acceleration), so the mean of w . (v(s) - v(r))
  over s in window k + 1 and r in window k is at most c_w times the mean of
  s - r, (t_k + t_(k+1)) / 2. With the e's at their worst (|w . e| <= |e|):
  |w . (d_(k+1) / t_(k+1) - d_k / t_k)| <= c_w (t_k + t_(k+1)) / 2
  + (|e_(k+1)| + |e_k|) / t_(k+1) + (|e_k| + |e_(k-1)|) / t_k,
  taken along each axis and along the turn's normal d_(k+1) / |d_(k+1)| -
  d_k / |d_k|;
- the same holds for any two windows a < b, with the gap between their
  middles (t_a / 2 + the windows between + t_b / 2) and the e's at their
  four ends: windows two apart are held to it too in one run (SKIP), which
  keeps some of what the e's share between neighbouring pairs (relaxed
  pair by pair, each e_k counts at its worst in both of its pairs);
- at rest at both ends: v(0) = 0, so |w . m_1| <= c_w t_1 / 2, i.e. |w . d_1|
  - |e_1| <= c_w t_1^2 / 2, along the axes and d_1; the same for the last;
- the least sum of t_k these allow is a lower bound on T. It is taken by a
  dynamic programme over a grid of t per window (boxes, each RATIO wider
  than the last, from the least t the feed and axes allow, the last box
  open; the state the last window's box, or the last two's with SKIP) that
  can only come out low: boxes count as feasible together if the
  constraint can hold anywhere in them (the least |..| over the boxes
  against the most room), and a box costs its lower corner. Windows of
  0.25, 0.4, 0.5, 1 and 2 mm (fewer, longer ones past MOST windows), and
  windows from block end to block end (blocks longer than 0.5, 0.7 or 1 mm
  cut into equal pieces), give the bounds; the largest is taken. A window
  across a corner reads only its chord, which cuts the corner; one that
  ends at the corner reads the turn itself (sharp: 12.483 -> 13.608 s). A
  point is left out where its window would be shorter than SPREAD times
  the E at its two ends (that merges two windows, which is again a window).
  The placement that gives the most is run again on finer boxes (0.2 %)
  round the times its first pass took, every box edge of the first pass
  kept, so every t still lies in a box and the result is again a bound,
  with less of the grid's 2 % given away (sharp 13.608 -> 13.777 s, tiny
  3.499 -> 3.503). The windows gain on curves sampled by short chords
  (tiny: 2.271 -> 3.503 s) and, ending at block ends, on sharp corners
  between short lines (sharp); where corners between long lines decide the
  time the trapezoids stay the larger (walk, square). Both are loose on tiny
  still: bench/piece-lp's optimum on 80-block pieces is 1.17-1.38 times
  the windows. Tried and not kept: each e_k's part along the curve's normal
  kept the same in both of its pairs (in five cells of [-P, P], a state of
  the programme beside the window's box) gained under 1 % at the window
  lengths that give the most, so the pairwise relaxation of the e's is not
  where the rest lies.
Checked: on a polyline of 0.1 mm chords round three quarters of a circle of
radius 2 mm at F6000 it comes out above the trapezoids and below the time
of a motion on the circle at the speed sqrt(A R / sqrt 2) (every axis
within A: the acceleration's norm is at most A), and never above our
planner's time or bench/piece-lp's achievable optimum
(tests/tools/planner-bound-check). Needs python3-numpy.

Motion is read from `cnc-run parse --canon`: STRAIGHT_FEED and ARC_FEED in the
XY plane (G17) with a helical Z, as bench/gen-planner.py writes them.

usage: planner-bound.py PROGRAM INI [--cnc-run PATH] [--detail]  -> prints seconds
"""
import math
import re
import subprocess
import sys

import numpy as np


def ini_limits(path):
    sec, lim = None, {}
    for line in open(path):
        line = line.split("#")[0].strip()
        m = re.match(r"^\[(\w+)\]$", line)
        if m:
            sec = m.group(1)
            continue
        m = re.match(r"^(\w+)\s*=\s*(\S+)", line)
        if m and sec and sec.startswith("AXIS_") and m.group(1) in ("MAX_VELOCITY", "MAX_ACCELERATION"):
            lim.setdefault(sec[5], {})[m.group(1)] = float(m.group(2))
    try:
        return ([lim[a]["MAX_VELOCITY"] for a in "XYZ"], [lim[a]["MAX_ACCELERATION"] for a in "XYZ"])
    except KeyError as e:
        sys.exit("planner-bound: %s: [AXIS_%s] MAX_VELOCITY / MAX_ACCELERATION missing" % (path, e))


def moves(prog, cnc_run):
    out = subprocess.run([cnc_run, "parse", prog, "--canon", "-"], capture_output=True, text=True)
    if out.returncode:
        sys.exit("planner-bound: %s" % out.stderr.strip())
    pos, feed, tol, segs = [0.0, 0.0, 0.0], None, 0.0, []
    for line in out.stdout.split("\n"):
        m = re.match(r"^(\w+)\((.*)\)$", line.strip())
        if not m:
            continue
        name, args = m.group(1), [a.strip() for a in m.group(2).split(",")]
        if name == "SET_FEED_RATE":
            feed = float(args[0]) / 60.0
        elif name == "SET_MOTION_CONTROL_MODE" and len(args) > 1:
            tol = float(args[1])
        elif name in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            end = [float(a) for a in args[:3]]
            if name == "STRAIGHT_FEED" and end != pos:
                segs.append(("line", list(pos), end, feed))
            pos = end
        elif name == "ARC_FEED":
            x, y, cx, cy, rot, z = (float(a) for a in args[:6])
            segs.append(("arc", list(pos), [x, y, z], feed, (cx, cy), int(rot)))
            pos = [x, y, z]
    return segs, tol


def sub(a, b):
    return [p - q for p, q in zip(a, b)]


def norm(a):
    return math.sqrt(sum(c * c for c in a))


def unit(a):
    n = norm(a)
    return [c / n for c in a] if n > 0 else [0.0, 0.0, 0.0]


def moving_norm(amax, *dirs):
    """The norm of the limits of the axes any of dirs moves."""
    return math.sqrt(sum(amax[i] ** 2 for i in range(3) if any(abs(d[i]) > 1e-12 for d in dirs)))


def arc_within(r, sweep, tol):
    """The flattest turn within tol of an arc of radius r and sweep: its
    radius, and how much of the lines either side of the arc it takes (its
    turning points lie beyond the arc's ends, on their tangents)."""
    if tol <= 0:
        return r, 0.0
    if sweep >= math.pi - 1e-9:
        return r + tol, 0.0
    half = sweep / 2
    reach = tol / (1 / math.cos(half) - 1)
    return r + reach, reach * math.tan(half)


def arc_of(seg):
    """An ARC_FEED's centre (x, y), radius, start and end angles and sweep
    (rad, its whole turns included) and whether it runs counter-clockwise."""
    (cx, cy), rot = seg[4], seg[5]
    s, e = seg[1], seg[2]
    r = math.hypot(s[0] - cx, s[1] - cy)
    a0 = math.atan2(s[1] - cy, s[0] - cx)
    a1 = math.atan2(e[1] - cy, e[0] - cx)
    ccw = rot > 0
    sweep = (a1 - a0) % (2 * math.pi) if ccw else (a0 - a1) % (2 * math.pi)
    if sweep < 1e-12:
        sweep = 2 * math.pi
    sweep += 2 * math.pi * (abs(rot) - 1)
    return cx, cy, r, a0, a1, sweep, ccw


def geometry(seg, vmax, amax, tol=0.0):
    """(length, speed cap, acceleration cap, entry tangent, exit tangent,
    radius or inf, the length taken from the segments either side)"""
    if seg[0] == "line":
        d = sub(seg[2], seg[1])
        u = unit(d)
        vcap = min([seg[3]] + [vmax[i] / abs(u[i]) for i in range(3) if abs(u[i]) > 1e-12])
        acap = min(amax[i] / abs(u[i]) for i in range(3) if abs(u[i]) > 1e-12)
        return norm(d), vcap, acap, u, u, math.inf, 0.0
    s, e = seg[1], seg[2]
    _, _, r, a0, a1, sweep, ccw = arc_of(seg)
    dz = e[2] - s[2]
    sg = 1 if ccw else -1

    def tang(a):
        return unit([-sg * math.sin(a) * r * sweep, sg * math.cos(a) * r * sweep, dz])
    an = moving_norm(amax, (1, 1, dz))
    # within P the path may turn on a wider circle than the arc's (the
    # flattest one within P: as much wider as the corner model's circle),
    # and run as close as r - P round the centre
    wide, spill = arc_within(r, sweep, tol)
    vcap = min(seg[3], math.sqrt(an * wide), *vmax)
    inner = math.hypot(max(r - tol, 0.0) * sweep, dz)
    return inner, vcap, an, tang(a0), tang(a1), r, spill


def corner(phi, tol, near, an, aw):
    """The fastest a turn by phi within tol of two lines can pass at its
    slowest, and the most it can shorten the path (the module docstring).
    near: the shorter line's length; an: the norm of the moving axes' limits;
    aw: the most acceleration the axes give along u2 - u1."""
    half = phi / 2
    c, sn = math.cos(half), math.sin(half)
    # the circle tangent to both outer edges whose middle reaches the inner
    # edges' meeting point: 2 P / (1 - cos(phi / 2))
    circle = an * tol / math.sin(half / 2) ** 2
    # the constant-acceleration turn between the outer edges, at its middle
    parabola = 4 * aw * tol * c / (sn * sn)
    return math.sqrt(max(circle, parabola)), 2 * min(tol * math.tan(half), max(near, 0.0))


def profile(g, length, stops, vj=None):
    """The fastest trapezoids over the segments with junction speed caps vj
    (default: the segments' own caps), at rest at the start, the end and the
    junctions in stops."""
    n = len(g)
    if vj is None:
        vj = [0.0] + [min(g[k - 1][1], g[k][1]) for k in range(1, n)] + [0.0]
    vj = [0.0 if k in stops else c for k, c in enumerate(vj)]
    v = list(vj)
    for k in range(1, n + 1):
        v[k] = min(v[k], math.sqrt(v[k - 1] ** 2 + 2 * g[k - 1][2] * max(length[k - 1], 0.0)))
    for k in range(n - 1, -1, -1):
        v[k] = min(v[k], math.sqrt(v[k + 1] ** 2 + 2 * g[k][2] * max(length[k], 0.0)))
    t = 0.0
    for k in range(n):
        L, vc, a = max(length[k], 0.0), g[k][1], g[k][2]
        v0, v1 = min(v[k], vc), min(v[k + 1], vc)
        vp = min(vc, math.sqrt((2 * a * L + v0 * v0 + v1 * v1) / 2))
        d_acc = (vp * vp - v0 * v0) / (2 * a)
        d_dec = (vp * vp - v1 * v1) / (2 * a)
        cruise = max(L - d_acc - d_dec, 0.0)
        t += (vp - v0) / a + (vp - v1) / a + (cruise / vp if vp > 0 else 0.0)
    return t


def bound(segs, tol, vmax, amax):
    g = [geometry(s, vmax, amax, tol) for s in segs]
    n = len(g)
    length = [x[0] for x in g]
    # an arc's flattest turn within P reaches onto the segments either side
    for k in range(n):
        if g[k][6] > 0:
            if k > 0:
                length[k - 1] -= g[k][6]
            if k + 1 < n:
                length[k + 1] -= g[k][6]
    vj = [0.0] * (n + 1)          # junction speed caps; 0 at start and end
    for k in range(1, n):
        a, b = g[k - 1], g[k]
        c = max(-1.0, min(1.0, sum(p * q for p, q in zip(a[4], b[3]))))
        phi = math.acos(c)
        cap = min(a[1], b[1])
        if phi > 1e-9:
            if tol <= 0:
                cap = 0.0
            else:
                du = sub(b[3], a[4])
                dn = norm(du)
                v, cut = corner(phi, tol, min(length[k - 1], length[k]), moving_norm(amax, a[4], b[3]),
                                sum(amax[i] * abs(du[i]) / dn for i in range(3)))
                cap = min(cap, v)
                length[k - 1] -= cut / 2
                length[k] -= cut / 2
        vj[k] = cap
    return profile(g, length, (), vj)

# ---- the window bound ------------------------------------------------------


class Path:
    """The programmed path by arc length: points of its blocks, exact on lines
    and arcs (helices), for the window bound."""

    def __init__(self, segs):
        self.segs, self.s0, self.len = [], [], []
        s = 0.0
        for sg in segs:
            if sg[0] == "line":
                L = norm(sub(sg[2], sg[1]))
                self.segs.append(("line", sg[1], sg[2]))
            else:
                st, e = sg[1], sg[2]
                cx, cy, r, a0, _, sweep, ccw = arc_of(sg)
                L = math.hypot(r * sweep, e[2] - st[2])
                self.segs.append(("arc", (cx, cy, r, a0, (1 if ccw else -1) * sweep, st[2], e[2])))
            self.s0.append(s)
            self.len.append(L)
            s += L
        self.total = s
        self.s0 = np.array(self.s0)

    def at(self, s):
        """Points at arc lengths s (an array)."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.total)
        idx = np.clip(np.searchsorted(self.s0, s, side="right") - 1, 0, len(self.segs) - 1)
        out = np.empty((len(s), 3))
        for i in np.unique(idx):
            m = idx == i
            f = (s[m] - self.s0[i]) / self.len[i] if self.len[i] > 0 else np.zeros(m.sum())
            f = np.clip(f, 0.0, 1.0)[:, None]
            g = self.segs[i]
            if g[0] == "line":
                a, b = np.array(g[1]), np.array(g[2])
                out[m] = a + f * (b - a)
            else:
                cx, cy, r, a0, sw, z0, z1 = g[1]
                ang = a0 + f[:, 0] * sw
                out[m] = np.stack([cx + r * np.cos(ang), cy + r * np.sin(ang), z0 + f[:, 0] * (z1 - z0)], axis=1)
        return out


RATIO = 1.02             # the DP's grid of window times: each box this much wider than the last
SPAN = 50.0              # from the fastest a window can be run to this many times that (then one open box)
FINE, FINE_N = 1.002, 70  # a refining pass: boxes this much wider than the last, this many either side


def windows_bound(pts, err, feed, vmax, amax, skip=False, ratio=RATIO, span=SPAN, refine=0):
    """The least sum of window times t_k that the constraints of the docstring
    allow, pts the cross-sections' points (the first and last the program's
    ends, at rest), err their E (0 at the ends); computed on a grid of t per
    window so that it can only come out low: a pair of boxes counts as
    feasible if the constraints can hold anywhere in it, and a box costs its
    lower corner."""
    pts, err = np.asarray(pts), np.asarray(err)
    d = np.diff(pts, axis=0)
    n = len(d)
    dn = np.linalg.norm(d, axis=1)
    vmax, amax = np.asarray(vmax, float), np.asarray(amax, float)
    slack = err[1:] + err[:-1]                       # |e_k - e_{k-1}| at most this
    if np.any(dn <= slack):
        return None
    # the fastest each window can be run: feed and every axis's velocity
    tlo = (dn - slack) / feed
    with np.errstate(divide="ignore", invalid="ignore"):
        tlo = np.maximum(tlo, np.max(np.where(np.abs(d) > slack[:, None], (np.abs(d) - slack[:, None]) / vmax, 0), axis=1))
    m = int(math.ceil(math.log(span) / math.log(ratio))) + 1
    grid = tlo[:, None] * ratio ** np.arange(m)[None, :]         # box b of window k: [grid[k,b], grid[k,b+1]]
    top = np.concatenate([grid[:, 1:], np.full((n, 1), np.inf)], axis=1)
    axes = np.eye(3)

    def dirs(k0, k1):
        """Directions the pair's velocity change is read along: the axes and
        the turn's normal (any unit w gives one: w . (m_b - m_a) at most
        sum_j amax_j |w_j| times the gap)."""
        ws = [axes[j] for j in range(3)]
        u = d[k1] / dn[k1] - d[k0] / dn[k0]
        if np.linalg.norm(u) > 1e-9:
            ws.append(u / np.linalg.norm(u))
        return ws

    def rest(k, lo, hi):
        """Boxes of the first or last window a motion at rest at its outer end
        can be in: w . m_k at most sum_j amax_j |w_j| t_k / 2."""
        ok = np.ones(m, dtype=bool)
        for w in list(axes) + [d[k] / dn[k]]:
            c = float(np.abs(w) @ amax)
            ok &= np.abs(w @ d[k]) - slack[k] <= c * hi * hi / 2 * (1 + 1e-12) + 1e-15
        return ok

    def interval(alpha, lo, hi):
        """alpha / t over t in [lo, hi] (hi may be inf)."""
        a = alpha / lo
        b = np.where(np.isinf(hi), 0.0, alpha / np.where(np.isinf(hi), 1.0, hi))
        return np.minimum(a, b), np.maximum(a, b)

    def need(k0, k1):
        """For windows k0 < k1 in boxes (rows: k0's, columns: k1's), the
        least time the windows between them must take for w . (m_k1 - m_k0)
        to be within c_w times the gap between their middles along every
        direction: -inf where the boxes allow it anyway."""
        th, uh = top[k0][:, None], top[k1][None, :]
        tl, ul = grid[k0][:, None], grid[k1][None, :]
        out = np.full((m, m), -np.inf)
        with np.errstate(invalid="ignore"):
            for w in dirs(k0, k1):
                c = float(np.abs(w) @ amax)
                a1, b1 = interval(float(w @ d[k1]), ul, uh)
                a0, b0 = interval(float(w @ d[k0]), tl, th)
                least = np.maximum(0.0, np.maximum(a1 - b0, a0 - b1))
                room = c * (th + uh) / 2 + (err[k1 + 1] + err[k1]) / ul + (err[k0 + 1] + err[k0]) / tl
                out = np.maximum(out, (least - room * (1 + 1e-12) - 1e-15) / c)
        return out

    def chain():
        """The least cost over the boxes, each window held to the one before,
        and the box of each window it takes."""
        first = rest(0, grid[0], top[0])
        last = rest(n - 1, grid[n - 1], top[n - 1])
        cost = np.where(first, grid[0], np.inf)
        back = []
        for k in range(n - 1):
            c = np.where(need(k, k + 1) <= 0, cost[:, None], np.inf)
            back.append(c.argmin(axis=0))
            cost = c.min(axis=0) + grid[k + 1]
        cost = np.where(last, cost, np.inf)
        b = int(cost.argmin())
        boxes = [b]
        for bp in reversed(back):
            b = int(bp[b])
            boxes.append(b)
        return float(cost.min()), np.array(boxes[::-1])

    if not skip or n < 3:
        best, boxes = chain()
        edges = grid
        for _ in range(refine):
            if not math.isfinite(best):
                break
            # finer boxes round the times the last pass took, every earlier
            # box edge kept: every t still lies in some box, so the result is
            # a bound again, and no lower
            at = grid[np.arange(n), boxes]
            fine = at[:, None] * FINE ** np.arange(-FINE_N, FINE_N + 1)[None, :]
            edges = np.concatenate([edges, np.maximum(fine, tlo[:, None])], axis=1)
            grid = np.sort(edges, axis=1)
            top = np.concatenate([grid[:, 1:], np.full((n, 1), np.inf)], axis=1)
            m = grid.shape[1]
            best, boxes = chain()
        return best
    # the state: the boxes of the last two windows, and every window also
    # held to the one two back (the gap between their middles: half of each
    # and the whole of the one between)
    first = rest(0, grid[0], top[0])
    last = rest(n - 1, grid[n - 1], top[n - 1])
    cost = np.where(first[:, None] & (need(0, 1) <= 0), grid[0][:, None] + grid[1][None, :], np.inf)
    for k in range(1, n - 1):
        far = need(k - 1, k + 1)                                  # (a, c)
        held = far[:, None, :] <= top[k][None, :, None] * (1 + 1e-12)   # (a, b, c)
        prev = np.where(held, cost[:, :, None], np.inf).min(axis=0)      # (b, c)
        cost = np.where(need(k, k + 1) <= 0, prev, np.inf) + grid[k + 1][None, :]
    return float(np.where(last[None, :], cost, np.inf).min())


LENGTHS = (0.25, 0.4, 0.5, 1.0, 2.0)   # window lengths tried, mm (the largest bound is taken)
SKIP = (0.4,)             # and with each window held to the one two back too (slower)
MOST = 600              # windows at most (longer ones on long paths: time)
VERTEX_PIECES = (0.5, 0.7, 1.0)   # windows from block end to block end, blocks cut into pieces of at most this
REFINE = 1               # refining passes on the best placement
SPREAD = 1.5            # a window at least this many times the sum of its ends' E


def seg_dist(pts, a, b):
    """Distances of points pts (n, 3) from the segments a[j] -> b[j]: (n, m)."""
    ab = b - a
    ll = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    rel = pts[:, None, :] - a[None, :, :]
    f = np.clip(np.einsum("nmj,mj->nm", rel, ab) / ll[None, :], 0.0, 1.0)
    return np.linalg.norm(rel - f[:, :, None] * ab[None, :, :], axis=2)


def jump_reach(path, k, tol):
    """Beside an arc, by samples: for jumps from block k - 1 into block k
    (their ends within 2 P of each other, at most half a turn of an arc from
    the vertex), the most P plus the path's height over such a jump's chord,
    and the farthest from the vertex (along the path) either end lies."""
    at = path.s0[k]
    step, coarse = tol / 4, 4 * tol

    def side(i, sign, every, limit=math.inf):
        g = path.segs[i]
        most = min(path.len[i], limit)
        if g[0] == "arc":
            most = min(most, path.len[i] * math.pi / abs(g[1][4]) * (1 - 1e-9))
        d = np.arange(0.0, most + every / 2, every)
        return d, path.at(at + sign * d)

    def pairs(pa, pb, every):
        return np.linalg.norm(pa[:, None, :] - pb[None, :, :], axis=2) <= 2 * tol + 2 * every

    # where jumps can be, on coarse samples first (a fine pair within 2 P has
    # coarse samples within 2 P + 2 coarse steps), then every P / 4 up to there
    da, pa = side(k - 1, -1, coarse)
    db, pb = side(k, 1, coarse)
    near = pairs(pa, pb, coarse)
    da, pa = side(k - 1, -1, step, da[np.nonzero(near.any(axis=1))[0].max()] + coarse)
    db, pb = side(k, 1, step, db[np.nonzero(near.any(axis=0))[0].max()] + coarse)
    near = pairs(pa, pb, step)
    height, reach = 0.0, 0.0
    for i in np.nonzero(near.any(axis=1))[0]:
        js = np.nonzero(near[i])[0]
        a = np.repeat(pa[i][None, :], len(js), axis=0)
        b = pb[js]
        # the path between: block k - 1's samples from A to the vertex, and
        # block k's from the vertex to B (those beyond B masked out)
        h = seg_dist(pa[:i + 1], a, b).max(axis=0)
        hb = np.where(np.arange(js.max() + 1)[:, None] <= js[None, :], seg_dist(pb[:js.max() + 1], a, b), 0.0)
        height = max(height, float(np.maximum(h, hb.max(axis=0)).max()))
        reach = max(reach, da[i], db[js].max())
    # a jump's ends and the path may lie between samples: a step more of each
    return tol + height + step, reach + step


def junctions(segs, path, tol, vmax, amax):
    """Where a jump of the walker between two blocks may leave it more than P
    from the motion (the docstring's E): per junction, its arc length, the E
    of every point a jump across it can pass, and how far along the path
    either side such a point can lie. Between lines exactly; beside an arc
    (which may bend back towards the other block) by samples."""
    out = []
    for k in range(1, len(segs)):
        if path.segs[k - 1][0] == "arc" or path.segs[k][0] == "arc":
            e, reach = jump_reach(path, k, tol)
            out.append((path.s0[k], e, reach))
            continue
        g0, g1 = geometry(segs[k - 1], vmax, amax), geometry(segs[k], vmax, amax)
        c = max(-1.0, min(1.0, sum(p * q for p, q in zip(g0[4], g1[3]))))
        phi = math.acos(c)
        if phi <= 1e-9:
            continue
        theta = math.pi - phi                       # the angle between the blocks at the vertex
        # a jump's ends lie within 2 P of each other, each within 2 P of the
        # other block: no further from the vertex than this along a line
        reach = 2 * tol / math.sin(min(theta, math.pi / 2)) if theta > 1e-9 else math.inf
        reach = min(reach, path.len[k - 1] + path.len[k])
        e = tol / math.cos(phi / 2) if phi < math.pi - 1e-6 else math.inf
        # at most P + the distance from the jump's chord of the vertex
        out.append((path.s0[k], min(e, tol + reach), reach))
    return out


def point_errors(path, s, tol, joints):
    """E per path point at arc lengths s: how far from it the motion may be
    when the walker passes it (0 at the program's ends, at rest there)."""
    s = np.asarray(s, dtype=float)
    err = np.full(len(s), float(tol))
    idx = np.clip(np.searchsorted(path.s0, s, side="right") - 1, 0, len(path.segs) - 1)
    for i, g in enumerate(path.segs):
        if g[0] == "arc":
            r = abs(g[1][2])
            err[idx == i] = tol + r - math.sqrt(max(r * r - tol * tol, 0.0)) if r > tol else tol + r
    for at, e, reach in joints:
        near = np.abs(s - at) <= reach * (1 + 1e-9) + 1e-12
        err[near] = np.maximum(err[near], e)
    err[0] = err[-1] = 0.0
    return err


def spread(path, s, err):
    """The points of s (its first and last kept) with every window longer
    than SPREAD times the E at its ends, so the window bound's slack leaves
    it some length; dropping a point only merges two windows."""
    pts = path.at(s)
    keep = [0]
    for i in range(1, len(s) - 1):
        if np.linalg.norm(pts[i] - pts[keep[-1]]) > SPREAD * (err[i] + err[keep[-1]]) and \
                np.linalg.norm(pts[-1] - pts[i]) > SPREAD * (err[i] + err[-1]):
            keep.append(i)
    keep.append(len(s) - 1)
    return np.asarray(s)[keep], err[keep]


def window_bounds(segs, tol, vmax, amax):
    """{windows: the window bound} (the docstring): windows of each length in
    LENGTHS along the path from its start, the last one taking the rest; and
    windows from block end to block end, longer blocks cut into equal pieces
    of at most each of VERTEX_PIECES (a window's chord is then its path,
    where one across a corner cuts it)."""
    if not segs or tol <= 0:
        return {}
    if any(norm(sub(a[2], b[1])) > 1e-9 for a, b in zip(segs, segs[1:])):
        return {}             # a rapid in between: the blocks are not one path
    feed = max(sg[3] for sg in segs)
    path = Path(segs)
    joints = junctions(segs, path, tol, vmax, amax)
    out = {}

    placed = {}

    def run(name, s, skip=False):
        s, err = spread(path, s, point_errors(path, s, tol, joints))
        if len(s) < 3:
            return
        b = windows_bound(path.at(s), err, feed, vmax, amax) if not skip else \
            windows_bound(path.at(s), err, feed, vmax, amax, skip=True, ratio=1.03, span=30.0)
        if b is not None:
            out[name] = b
            if not skip:
                placed[name] = (s, err)

    for length in sorted(set(max(x, path.total / MOST) for x in LENGTHS)):
        n = int(path.total / length)
        if n < 2:
            continue
        s = np.concatenate([np.arange(n) * length, [path.total]])
        run("%g mm" % length, s)
        if length in SKIP:
            run("%g mm, every other too" % length, s, skip=True)
    for piece in VERTEX_PIECES:
        s = []
        for s0, L in zip(path.s0, path.len):
            k = max(1, int(math.ceil(L / max(piece, path.total / MOST))))
            s.extend(s0 + L * np.arange(k) / k)
        run("blocks in %g mm" % piece, np.array(s + [path.total]))
    # the placement that gave the most, on finer boxes (REFINE passes): the
    # grid's boxes cost up to RATIO of each window's time
    if placed:
        name = max(placed, key=lambda k: out[k])
        s, err = placed[name]
        b = windows_bound(path.at(s), err, feed, vmax, amax, refine=REFINE)
        if b is not None:
            out[name + ", finer"] = b
    return out


def main():
    args = sys.argv[1:]
    cnc_run = "build/cnc-run"
    if "--cnc-run" in args:
        i = args.index("--cnc-run")
        cnc_run = args[i + 1]
        del args[i:i + 2]
    detail = "--detail" in args
    if detail:
        args.remove("--detail")
    if len(args) != 2:
        sys.exit(__doc__.strip().split("\n")[-1])
    vmax, amax = ini_limits(args[1])
    segs, tol = moves(args[0], cnc_run)
    old = bound(segs, tol, vmax, amax)
    win = window_bounds(segs, tol, vmax, amax)
    if detail:
        print("trapezoids %.3f; windows %s" % (old, "; ".join("%s %.3f" % kv for kv in win.items())),
              file=sys.stderr)
    print("%.3f" % max([old] + list(win.values())))


if __name__ == "__main__":
    main()
