#!/usr/bin/env python3
"""tests/machine/check-limits.py INI TRACE: every commanded position of the
trace within its axis's MIN_LIMIT .. MAX_LIMIT (wrapped rotary axes have
none), every actual position within them by at most FERROR. Prints nothing
and exits 0 when all are; else one line naming the first row and axis that
is not, exit 1."""
import configparser
import subprocess
import sys

ini = configparser.ConfigParser(inline_comment_prefixes=('#',))
ini.optionxform = str
ini.read(sys.argv[1])
coords = ini.get('TRAJ', 'COORDINATES', fallback='XYZ').replace(' ', '')
lim = {}
for ax in coords:
    sec = 'AXIS_' + ax
    if ini.get(sec, 'WRAPPED_ROTARY', fallback='0') == '1':
        continue
    lim[ax.lower()] = (float(ini.get(sec, 'MIN_LIMIT')), float(ini.get(sec, 'MAX_LIMIT')),
                       float(ini.get(sec, 'FERROR')))
# awk reads the rows: a long program's trace has millions of them
with open(sys.argv[2]) as f:
    head = f.readline().strip().split(',')
prog = []
for ax, (lo, hi, fe) in lim.items():
    c, a = head.index(ax + '_cmd') + 1, head.index(ax + '_act') + 1
    prog.append('if ($%d < %r || $%d > %r || $%d < %r || $%d > %r) { '
                'printf "row %%d (t %%s, line %%s): %s command %%.6f / actual %%.6f outside %g .. %g\\n", '
                'NR, $1, $2, $%d, $%d; bad = 1; exit 1 }'
                % (c, lo - 1e-9, c, hi + 1e-9, a, lo - fe, a, hi + fe, ax.upper(), lo, hi, c, a))
script = 'NR > 1 { ' + ' '.join(prog) + ' } END { exit bad }'
sys.exit(subprocess.run(['awk', '-F,', script, sys.argv[2]]).returncode)
