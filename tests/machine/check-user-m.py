#!/usr/bin/env python3
"""check-user-m.py TRACE LOG: user-codes-files/userm.ngc's run (--clock real).

M101 (user-codes-files/mcodes/M101) appends "P Q start end" to LOG and takes
0.3 s. Checked: it ran twice, with P1.5 Q2 and then the -1 -1 LinuxCNC
passes for absent words; the machine stood still at X10 and at X20 for at
least the 0.3 s each run took (the queue drained first, motion waited for
its exit); and the machine's time from leaving X10 to reaching X20 is the
wall time between the first run's end and the second's start. Prints
PASS/FAIL lines."""
import csv
import sys

trace, log = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(trace)))
recs = [l.split() for l in open(log) if l.strip()]


def result(name, ok, why=""):
    print(("PASS " if ok else "FAIL ") + "user-codes/" + name + ("" if ok else ": " + why))


args = [r[:2] for r in recs]
result("m101-args", args == [["1.500000", "2.000000"], ["-1.000000", "-1.000000"]],
       "P/Q passed %s, want 1.500000 2.000000 then -1.000000 -1.000000" % args)


def rest_at(x):
    """first and last t of the rows standing still at X x"""
    ts = [float(r["t"]) for r in rows
          if abs(float(r["x_cmd"]) - x) < 1e-6 and float(r["v"]) == 0 and r["line"] != "0"]
    return (ts[0], ts[-1]) if ts else (None, None)


(a0, a1), (b0, b1) = rest_at(10.0), rest_at(20.0)
if a0 is None or b0 is None or len(recs) != 2:
    result("at-rest", False, "no rest at X10 (%s) or X20 (%s), %d runs" % (a0, b0, len(recs)))
    sys.exit(0)
result("at-rest", a1 - a0 >= 0.29 and b1 - b0 >= 0.29,
       "the machine stood %.3f s at X10 and %.3f s at X20, each run took 0.3 s"
       % (a1 - a0, b1 - b0))
moving = b0 - a1
between = float(recs[1][2]) - float(recs[0][3])
result("in-order-with-motion", abs(moving - between) < 0.15,
       "X10 to X20 took %.3f s of machine time, %.3f s passed between the runs"
       % (moving, between))
