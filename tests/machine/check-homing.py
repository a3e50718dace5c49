#!/usr/bin/env python3
"""tests/machine/check-homing.py INI TRACE: cnc-run run --home's trace on
the INI, checked against its homing keys. Per axis: the phases (the `home`
column's digit, enum nck_home_phase: 1 off the switch, 2 search, 3 back
off, 4 latch, 5 latched, 6 to HOME) come in LinuxCNC's order for the signs
of HOME_SEARCH_VEL and HOME_LATCH_VEL; the switch latches (the last latch
row's actual position, in the simulated machine's coordinates: nothing was
homed before) within |HOME_LATCH_VEL| x one servo period of the switch, on
the side the latch moves to; the command ends on HOME and the actual
position settles there within 1 um before the program moves; the
HOME_SEQUENCE groups start in ascending order, each group's axes on the
same servo period. Prints PASS/FAIL lines."""
import configparser
import csv
import sys

ini_path, trace_path = sys.argv[1], sys.argv[2]
ini = configparser.ConfigParser(inline_comment_prefixes=('#',))
ini.optionxform = str
ini.read(ini_path)
period = float(ini.get('EMCMOT', 'SERVO_PERIOD', fallback='1000000')) * 1e-9
coords = ini.get('TRAJ', 'COORDINATES', fallback='XYZ').replace(' ', '')
rows = list(csv.DictReader(open(trace_path)))
fails = 0


def check(ok, name, why=''):
    global fails
    print(('PASS homing/' if ok else 'FAIL homing/') + name + ('' if ok else ': ' + why))
    fails += not ok


def phase(r, k):
    return int(r['home'][k])


start = {}
for k, ax in enumerate(coords):
    sec = 'AXIS_' + ax
    key = lambda name, d='0': float(ini.get(sec, name, fallback=d))
    vs, vl = key('HOME_SEARCH_VEL'), key('HOME_LATCH_VEL')
    home, offset = key('HOME'), key('HOME_OFFSET')
    switch = float(ini.get('SIM', 'HOME_SWITCH_' + ax, fallback=str(offset)))
    col = ax.lower()
    seq = [phase(r, k) for r in rows]
    order = [p for i, p in enumerate(seq) if p and (i == 0 or seq[i - 1] != p)]
    on_at_start = (0.0 - switch) * (1 if vs > 0 else -1) >= 0
    want = ([1] if on_at_start else []) + [2] + ([3] if vl * vs > 0 else []) + [4]
    got = [p for p in order if p != 5]
    check(got == want + [6], ax + '-phases', 'phases %s, want %s' % (order, want + [6]))
    lat = [i for i in range(len(rows) - 1) if seq[i] == 4 and seq[i + 1] != 4]
    if not lat:
        check(False, ax + '-latch', 'no latch row')
        continue
    p = float(rows[lat[0]][col + '_act'])
    err = p - switch
    side = err * (1 if vl > 0 else -1) >= -1e-9   # past the switch in the latch's direction
    check(abs(err) <= abs(vl) * period * (1 + 1e-6) + 1e-9 and side, ax + '-latch-at-switch',
          'latched at %.6f, switch at %.6f: %.3f um off, allowed %.3f um' %
          (p, switch, err * 1e3, abs(vl) * period * 1e3))
    end = max(i for i in range(len(rows)) if seq[i])
    # the program (line 1: a dwell) starts at HOME; its last row before line 2
    still = [r for r in rows[end + 1:] if r['line'] in ('0', '1')]
    cmd = float(still[-1][col + '_cmd'])
    check(abs(cmd - home) < 1e-6, ax + '-command-at-home', 'command %.6f, HOME %.6f' % (cmd, home))
    act = float(still[-1][col + '_act'])
    check(abs(act - home) <= 0.001, ax + '-at-home-1um',
          'actual %.6f, HOME %.6f: %.3f um' % (act, home, (act - home) * 1e3))
    start[ax] = next(i for i in range(len(rows)) if seq[i])
    seqno = ini.get(sec, 'HOME_SEQUENCE', fallback=None)
    start[ax] = (abs(int(seqno)) if seqno is not None else 0, start[ax])

groups = {}
for ax, (s, i) in start.items():
    groups.setdefault(s, set()).add(i)
firsts = [sorted(groups[s]) for s in sorted(groups)]
check(all(len(g) == 1 for g in firsts), 'sequence-together', 'start rows per sequence %s' % firsts)
check(all(firsts[i][0] < firsts[i + 1][0] for i in range(len(firsts) - 1)), 'sequence-order',
      'start rows per sequence %s' % firsts)
sys.exit(1 if fails else 0)
