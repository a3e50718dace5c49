#!/usr/bin/env python3
"""check-kins.py BIN PROG INI TRACE: a run of PROG on a table-rotary-tilting
machine (xyzac-trt or xyzbc-trt, as the INI's [KINS] says) checked from its
trace, independently of the NCK's own transform:

- the tool tip, computed back from the commanded joints through the forward
  kinematics (written out here from LinuxCNC's trtfuncs formulas, with the
  INI's pivots and the trace's tool length), stays within 1 um of the
  programmed path (the canonical calls of `BIN parse`), the angles counted at
  100 mm of radius; the trace's own X Y Z A/B C agree with it;
- every joint stays within its [JOINT_n] (else [AXIS_L]) MIN_LIMIT and
  MAX_LIMIT, and its commanded velocity and acceleration (differences of
  the servo samples) within MAX_VELOCITY and MAX_ACCELERATION.
Prints PASS/FAIL lines."""
import re
import subprocess
import sys

import numpy as np

TIP_TOL = 1e-3      # mm
ANGLE_R = 100.0     # mm per radian: an angle error counts as its arc at this radius


def ini_sections(path):
    sec, out = None, {}
    for raw in open(path):
        line = raw.split('#')[0].strip()
        if not line:
            continue
        m = re.match(r'\[(.+)\]$', line)
        if m:
            sec = m.group(1).upper()
            out.setdefault(sec, {})
        elif '=' in line:
            k, v = line.split('=', 1)
            out[sec][k.strip().upper().replace('-', '_')] = v.strip()
    return out


def forward(kins, rot, off, j, tz):
    """LinuxCNC's xyzac/xyzbc KinematicsForward, written out term by term."""
    x, y, z, tilt, c = j
    xr, yr, zr = rot
    tr, cr = np.radians(tilt), np.radians(c)
    st, ct, sc, cc = np.sin(tr), np.cos(tr), np.sin(cr), np.cos(cr)
    if kins == 'xyzac-trt':
        dy, dz = off[1], off[2] + tz
        px = cc * (x - xr) + sc * ct * (y - dy - yr) + sc * st * (z - dz - zr) + sc * dy + xr
        py = -sc * (x - xr) + cc * ct * (y - dy - yr) + cc * st * (z - dz - zr) + cc * dy + yr
        pz = -st * (y - dy - yr) + ct * (z - dz - zr) + dz + zr
    else:
        dx, dz = off[0], off[2] + tz
        px = cc * ct * (x - dx - xr) + sc * (y - yr) - cc * st * (z - dz - zr) + cc * dx + xr
        py = -sc * ct * (x - dx - xr) + cc * (y - yr) + sc * st * (z - dz - zr) - sc * dx + yr
        pz = st * (x - dx - xr) + ct * (z - dz - zr) + dz + zr
    return np.stack([px, py, pz, tilt, c], axis=1)


def programmed(binary, prog, tilt_i):
    """The path as polyline vertices (x y z tilt c in machine coordinates)."""
    canon = subprocess.run([binary, 'parse', prog, '--canon', '-'], capture_output=True,
                           text=True, check=True).stdout
    num = r'(-?\d+\.\d+)'
    g5x = np.zeros(6)
    g92 = np.zeros(6)
    tool = np.zeros(6)
    pts = [np.zeros(5)]
    for line in canon.splitlines():
        vals = [float(v) for v in re.findall(num, line)]
        if line.startswith('SET_G5X_OFFSET('):
            g5x = np.array(vals[:6])
        elif line.startswith('SET_G92_OFFSET('):
            g92 = np.array(vals[:6])
        elif line.startswith('USE_TOOL_LENGTH_OFFSET('):
            tool = np.array(vals[:6])
        elif line.startswith(('STRAIGHT_FEED(', 'STRAIGHT_TRAVERSE(')):
            p = np.array(vals[:6]) + g5x + g92 + tool
            pts.append(np.array([p[0], p[1], p[2], p[tilt_i], p[5]]))
        elif line.startswith(('ARC_FEED(', 'STRAIGHT_PROBE(', 'NURBS')):
            sys.exit(f'FAIL kins/path: {line.split("(")[0]} is not handled by this check')
    return np.array(pts)


def dist_to_polyline(q, pts):
    """Distance of each row of q to the nearest segment of pts, in the scaled
    5-space (angles as arcs at ANGLE_R)."""
    scale = np.array([1, 1, 1, np.radians(1) * ANGLE_R, np.radians(1) * ANGLE_R])
    qs, ps = q * scale, pts * scale
    best = np.full(len(q), np.inf)
    for a, b in zip(ps[:-1], ps[1:]):
        ab = b - a
        n2 = ab @ ab
        t = np.zeros(len(q)) if n2 == 0 else np.clip((qs - a) @ ab / n2, 0, 1)
        d = np.linalg.norm(qs - (a + t[:, None] * ab), axis=1)
        best = np.minimum(best, d)
    return best


def main():
    binary, prog, ini_path, trace = sys.argv[1:5]
    ini = ini_sections(ini_path)
    kins = ini['KINS']['KINEMATICS'].split()[0].lower()
    tilt = 'a' if kins == 'xyzac-trt' else 'b'
    rot = [float(ini['KINS'].get(f'{a}_ROT_POINT', 0)) for a in 'XYZ']
    off = [float(ini['KINS'].get(f'{a}_OFFSET', 0)) for a in 'XYZ']
    period = float(ini['EMCMOT']['SERVO_PERIOD']) * 1e-9
    coords = ini['TRAJ']['COORDINATES'].upper()
    letters = ['x', 'y', 'z', tilt, 'c']

    head = open(trace).readline().strip().split(',')
    data = np.loadtxt(trace, delimiter=',', skiprows=1)
    col = {name: i for i, name in enumerate(head)}
    fails = 0

    def report(name, ok, what):
        nonlocal fails
        print(f"{'PASS' if ok else 'FAIL'} kins/{name}: {what}")
        fails += not ok

    jcmd = [data[:, col[f'j{a}_cmd']] for a in letters]
    jact = [data[:, col[f'j{a}_act']] for a in letters]
    tz = data[:, col['tool_z']]
    tip = forward(kins, rot, off, jcmd, tz)
    tip_act = forward(kins, rot, off, jact, tz)
    pts = programmed(binary, prog, 3 if tilt == 'a' else 4)
    d = dist_to_polyline(tip, pts)
    report('tip-on-path', d.max() <= TIP_TOL,
           f'tool tip from the commanded joints within {d.max() * 1e3:.4f} um of the '
           f'programmed path ({len(pts) - 1} moves, {len(d)} samples; limit 1 um)')
    da = dist_to_polyline(tip_act, pts)
    print(f'INFO kins/actual: tool tip from the actual joints within {da.max() * 1e3:.2f} um '
          f'of the path (the servos\' lag)')
    axes = np.stack([data[:, col[f'{a}_cmd']] for a in letters], axis=1)
    dc = np.abs(axes - tip).max()
    report('axes-agree', dc <= 1e-5, f'the trace\'s axes equal the forward kinematics of '
           f'its joints within {dc * 1e3:.5f} um')
    moved = [np.ptp(j) for j in jcmd[:3]]
    axmoved = [np.ptp(axes[:, i]) for i in range(3)]
    report('joints-differ', max(abs(np.ptp(jcmd[i]) - axmoved[i]) for i in range(3)) > 1,
           f'the joints took another path than the axes (ranges {moved} vs {axmoved})')

    for i, a in enumerate(letters):
        n = coords.index(a.upper())
        lim = dict(ini.get(f'AXIS_{a.upper()}', {}))
        lim.update(ini.get(f'JOINT_{n}', {}))
        lo, hi = float(lim['MIN_LIMIT']), float(lim['MAX_LIMIT'])
        vmax, amax = float(lim['MAX_VELOCITY']), float(lim['MAX_ACCELERATION'])
        j = jcmd[i]
        v = np.diff(j) / period
        acc = np.diff(j, 2) / period ** 2
        report(f'joint-{a}', j.min() >= lo - 1e-6 and j.max() <= hi + 1e-6 and
               np.abs(v).max() <= vmax * 1.001 and np.abs(acc).max() <= amax * 1.01,
               f'joint {n} ({a.upper()}) in [{j.min():.3f}, {j.max():.3f}] of [{lo:g}, {hi:g}], '
               f'|v| <= {np.abs(v).max():.3f} of {vmax:g}, |a| <= {np.abs(acc).max():.1f} of '
               f'{amax:g}')
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main())
