#!/usr/bin/env python3
"""tests/machine/check-adcai.py INI ADCBI_TRACE ADCAI_TRACE NAME: the ADCAI
run of a program against its ADCBI run. Checks that both end on the same
commanded point (to 1 nm) and that every axis of the ADCAI trace keeps its
MAX_VELOCITY and MAX_ACCELERATION (and MAX_JERK under PROFILE = scurve) from
the differences of the commanded positions, the trace's 6 printed decimals
allowed for. Reports how far the ADCAI path strays from the ADCBI path (its
corner rounding). Prints PASS/FAIL lines and one INFO line."""
import configparser
import math
import sys

ini_path, bi_path, ai_path, name = sys.argv[1:5]
ini = configparser.ConfigParser(inline_comment_prefixes=('#',), strict=False)
ini.optionxform = str
ini.read(ini_path)
T = float(ini.get('EMCMOT', 'SERVO_PERIOD')) * 1e-9
scurve = ini.get('PLANNER', 'PROFILE', fallback='trapezoid').lower() == 'scurve'
coords = ini.get('TRAJ', 'COORDINATES', fallback='XYZ').replace(' ', '')
lim = {}
for ax in coords:
    sec = 'AXIS_' + ax
    lim[ax.lower()] = (float(ini.get(sec, 'MAX_VELOCITY')), float(ini.get(sec, 'MAX_ACCELERATION')),
                       float(ini.get(sec, 'MAX_JERK', fallback='inf')))


def read(path):
    with open(path) as f:
        head = f.readline().strip().split(',')
        cols = [head.index(ax + '_cmd') for ax in lim]
        return [[float(r[c]) for c in cols] for r in (line.split(',') for line in f)]


bi, ai = read(bi_path), read(ai_path)
axes = list(lim)
ok = True

end_gap = max(abs(a - b) for a, b in zip(bi[-1], ai[-1]))
if end_gap <= 1.5e-6:
    print('PASS adcai/%s/same-end' % name)
else:
    ok = False
    print('FAIL adcai/%s/same-end: ADCAI ends %s, ADCBI %s' % (name, ai[-1], bi[-1]))

Q = 0.5e-6  # half the last printed digit
worst = [0.0, 0.0, 0.0]
where = [0, 0, 0]
for k in range(3, len(ai)):
    p0, p1, p2, p3 = ai[k - 3], ai[k - 2], ai[k - 1], ai[k]
    for j, ax in enumerate(axes):
        vmax, amax, jmax = lim[ax]
        v = (abs(p3[j] - p2[j]) - 2 * Q) / T / vmax
        a = (abs(p3[j] - 2 * p2[j] + p1[j]) - 4 * Q) / T ** 2 / amax
        jk = (abs(p3[j] - 3 * p2[j] + 3 * p1[j] - p0[j]) - 8 * Q) / T ** 3 / jmax
        for i, x in enumerate((v, a, jk)):
            if x > worst[i]:
                worst[i], where[i] = x, k
checked = worst[:3] if scurve else worst[:2]
if all(x <= 1.0 for x in checked):
    print('PASS adcai/%s/limits' % name)
else:
    ok = False
    print('FAIL adcai/%s/limits: worst velocity %.3f (row %d), acceleration %.3f (row %d), '
          'jerk %.3f (row %d) of the limits' % (name, worst[0], where[0] + 1, worst[1],
                                                 where[1] + 1, worst[2], where[2] + 1))

# How far the ADCAI path strays from ADCBI's: each ADCAI point's distance to
# the ADCBI polyline, found through a grid of the polyline's pieces. Points
# closer than STEP to the last one kept are left out: a chord that short
# cuts inside the tightest arc by well under a micrometre.
STEP, H = 0.05, 1.0


def thin(rows):
    out = []
    for p in rows:
        if not out or sum((p[j] - out[-1][j]) ** 2 for j in range(len(p))) >= STEP * STEP:
            out.append(p)
    if out and out[-1] != rows[-1]:
        out.append(rows[-1])
    return out


def cell(p):
    return tuple(int(math.floor(x / H)) for x in p[:3])


grid = {}
bt = thin(bi)
half = 0.0  # the longest piece's half: how far it reaches out of its cell
for k in range(1, len(bt)):
    a, b = bt[k - 1], bt[k]
    half = max(half, 0.5 * math.sqrt(sum((b[j] - a[j]) ** 2 for j in range(len(a)))))
    grid.setdefault(cell([(a[j] + b[j]) / 2 for j in range(len(a))]), []).append((a, b))
RINGS = {}
for dx in range(-12, 13):
    for dy in range(-12, 13):
        for dz in range(-12, 13):
            RINGS.setdefault(max(abs(dx), abs(dy), abs(dz)), []).append((dx, dy, dz))


def seg_dist(p, a, b):
    d = [b[j] - a[j] for j in range(len(p))]
    dd = sum(x * x for x in d)
    t = 0.0 if dd == 0 else max(0.0, min(1.0, sum((p[j] - a[j]) * d[j] for j in range(len(p))) / dd))
    return math.sqrt(sum((p[j] - a[j] - t * d[j]) ** 2 for j in range(len(p))))


def near(p):
    c = cell(p)
    best = math.inf
    for r in range(0, 13):
        # ring r's pieces lie at least (r - 1) H - half away
        if best < (r - 1) * H - half:
            break
        for dx, dy, dz in RINGS[r]:
            for a, b in grid.get((c[0] + dx, c[1] + dy, c[2] + dz), ()):
                best = min(best, seg_dist(p, a, b))
    return best


stray = max((near(p) for p in thin(ai)), default=0.0)
print('INFO adcai/%s: ADCAI path within %.4f mm of ADCBI\'s; worst velocity %.3f, '
      'acceleration %.3f, jerk %.3f of the limits' % (name, stray, worst[0], worst[1], worst[2]))
sys.exit(0 if ok else 1)
