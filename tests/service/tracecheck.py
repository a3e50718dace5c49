"""Checks on `cnc-run serve --trace` files for tests/service/run.

A trace row: t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion (mm, s, mm/s)."""

import math


def read(path):
    """[(t, line, (x, y, z) commanded, v)] of every row."""
    rows = []
    with open(path) as f:
        next(f)
        for ln in f:
            c = ln.split(",")
            rows.append((float(c[0]), int(c[1]), (float(c[2]), float(c[3]), float(c[4])),
                         float(c[8])))
    return rows


def moving_span(rows):
    idx = [i for i, r in enumerate(rows) if r[3] > 0]
    return (idx[0], idx[-1]) if idx else (0, -1)


def stops(rows, min_s):
    """Stretches of v = 0 lasting min_s or more between the first and the last
    row in motion: [(t_start, t_end)]."""
    a, b = moving_span(rows)
    out, start = [], None
    for i in range(a, b + 1):
        if rows[i][3] == 0:
            if start is None:
                start = i
        elif start is not None:
            if rows[i - 1][0] - rows[start][0] >= min_s:
                out.append((rows[start][0], rows[i - 1][0]))
            start = None
    return out


def points(rows):
    """Commanded points, consecutive repeats dropped."""
    out = []
    for r in rows:
        if not out or r[2] != out[-1]:
            out.append(r[2])
    return out


def seg_dist(p, a, b):
    d = [b[k] - a[k] for k in range(3)]
    w = [p[k] - a[k] for k in range(3)]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    t = 0.0 if dd == 0 else max(0.0, min(1.0, (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd))
    return math.sqrt(sum((w[k] - t * d[k]) ** 2 for k in range(3)))


def path_deviation(rows, ref_rows, window=400):
    """Largest distance from a commanded point of rows to the polyline of
    ref_rows's commanded points. Both run the same path in the same order, so
    each point is searched near where the previous one was found (a path that
    crosses itself does not fool it)."""
    pts, ref = points(rows), points(ref_rows)
    if len(ref) < 2:
        return float("inf")
    cur, worst = 0, 0.0
    for p in pts:
        lo, hi = max(0, cur - 20), min(len(ref) - 1, cur + window)
        best, at = float("inf"), cur
        for j in range(lo, hi):
            d = seg_dist(p, ref[j], ref[j + 1])
            if d < best:
                best, at = d, j
        if best > 1e-3:  # lost: search the whole reference once
            for j in range(len(ref) - 1):
                d = seg_dist(p, ref[j], ref[j + 1])
                if d < best:
                    best, at = d, j
        cur = at
        worst = max(worst, best)
    return worst


def near(a, b, tol=1e-6):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def safe_approach(rows, origin, z_safe, target):
    """None if the commanded path from origin goes Z up to z_safe with X Y
    still, then X Y at z_safe, then Z down onto target with X Y still; else
    why not."""
    pts = points(rows)
    i = 0
    while i < len(pts) and near(pts[i], origin):
        i += 1
    # Z up
    while i < len(pts) and pts[i][2] < z_safe - 1e-6:
        if not near(pts[i][:2], origin[:2]):
            return "X Y move before Z is up: %s" % (pts[i],)
        i += 1
    if i == len(pts):
        return "Z never reaches the safe height %g" % z_safe
    # X Y at the safe height
    while i < len(pts) and not near(pts[i][:2], target[:2]):
        if abs(pts[i][2] - z_safe) > 1e-6:
            return "Z leaves the safe height %g during the X Y move: %s" % (z_safe, pts[i])
        i += 1
    if i == len(pts):
        return "X Y never reach %s" % (target[:2],)
    # Z down
    while i < len(pts) and not near(pts[i], target):
        if not near(pts[i][:2], target[:2]):
            return "X Y move before Z is down at %s: %s" % (target, pts[i])
        i += 1
    if i == len(pts):
        return "never reaches the start of the line %s" % (target,)
    return None


def controlled_stop(rows, end, accel_step=3.0, vmax=200.0):
    """None if the commanded motion has no jump (speed between rows within the
    axes' velocity, the path velocity changing by no more than accel_step mm/s
    per row), comes to rest with v = 0 before the program's end point, after
    a ramp; else why not."""
    a, b = moving_span(rows)
    if b < 0:
        return "the trace shows no motion"
    for i in range(max(1, a), len(rows)):
        dt = rows[i][0] - rows[i - 1][0]
        if dt <= 0:
            return "time goes back at row %d" % (i + 1)
        step = math.dist(rows[i][2], rows[i - 1][2])
        if step / dt > vmax * 1.05:
            return "commanded jump of %.4f mm in %.4f s at t=%.3f" % (step, dt, rows[i][0])
        dv = abs(rows[i][3] - rows[i - 1][3])
        if dv > accel_step:
            return "v jumps by %.2f mm/s at t=%.3f" % (dv, rows[i][0])
    if rows[-1][3] != 0:
        return "the last row still moves (v %.3f)" % rows[-1][3]
    if near(rows[-1][2], end, 1e-3):
        return "the program ran to its end: no stop mid-program"
    vpeak = max(r[3] for r in rows[a:b + 1])
    ramp = 0
    for i in range(b, a - 1, -1):
        if rows[i][3] >= 0.9 * vpeak:
            break
        ramp += 1
    if ramp < 5:
        return "no ramp down at the end (%d rows)" % ramp
    return None


def axis_peaks(rows, t0=-math.inf, t1=math.inf):
    """Largest |velocity| and |acceleration| of each commanded axis (x, y,
    z) between t0 and t1, from the rows' differences: ([vx, vy, vz], [ax,
    ay, az]). Positions are printed to 1e-6 mm: at 1 ms rows that is
    1e-3 mm/s of velocity and 2 mm/s^2 of acceleration."""
    rows = [r for r in rows if t0 <= r[0] <= t1]
    vmax, amax = [0.0] * 3, [0.0] * 3
    prev_v = None
    for i in range(1, len(rows)):
        dt = rows[i][0] - rows[i - 1][0]
        if dt <= 0:
            continue
        v = [(rows[i][2][k] - rows[i - 1][2][k]) / dt for k in range(3)]
        for k in range(3):
            vmax[k] = max(vmax[k], abs(v[k]))
            if prev_v is not None:
                amax[k] = max(amax[k], abs(v[k] - prev_v[k]) / dt)
        prev_v = v
    return vmax, amax


def motions(rows, gap):
    """[(t_start, t_end)] of the stretches in motion (v > 0) that rest
    for at least gap seconds between them."""
    out = []
    for r in rows:
        if r[3] <= 0:
            continue
        if out and r[0] - out[-1][1] < gap:
            out[-1][1] = r[0]
        else:
            out.append([r[0], r[0]])
    return [tuple(x) for x in out]
