#!/usr/bin/env python3
"""Checks the trace of ncprograms/rotary-a.ngc on rt-config/sim-xyza.ini
(tests/machine/rotary): args PROGRAM INI TRACE. Prints PASS/FAIL lines."""
import configparser
import csv
import math
import sys

prog, ini, trace = sys.argv[1:4]
cfg = configparser.ConfigParser()
cfg.read(ini)
A_VEL = float(cfg["AXIS_A"]["MAX_VELOCITY"])
A_ACC = float(cfg["AXIS_A"]["MAX_ACCELERATION"])
T = float(cfg["EMCMOT"]["SERVO_PERIOD"]) * 1e-9

rows = list(csv.DictReader(open(trace)))
lines = {}
for n, text in enumerate(open(prog), 1):
    lines[text.strip()] = n


def ok(name, cond, why=""):
    print(("PASS" if cond else "FAIL") + " rotary/" + name + ("" if cond else ": " + why))


def col(k):
    return [float(r[k]) for r in rows]


a = col("a_cmd")
x, y, z, v = col("x_cmd"), col("y_cmd"), col("z_cmd"), col("v")
ok("trace-has-a", "a_cmd" in rows[0] and "a_act" in rows[0] and
   list(rows[0])[:10] == "t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion".split(","),
   "columns %s" % ",".join(list(rows[0])))


def of_line(text):
    n = str(lines[text])
    return [i for i, r in enumerate(rows) if r["line"] == n]


def speed(idx, axis):
    """top speed inside a move (the step into it belongs to the corner)"""
    return max(abs(axis[i] - axis[i - 1]) / T for i in idx[1:])


# per-axis limits of A over the whole run (commanded, one sample per period)
va = [(a[i] - a[i - 1]) / T for i in range(1, len(a))]
aa = [(va[i] - va[i - 1]) / T for i in range(1, len(va))]
ok("a-velocity-limit", max(abs(q) for q in va) <= A_VEL * 1.001,
   "A ran at %.3f deg/s, MAX_VELOCITY %.1f" % (max(abs(q) for q in va), A_VEL))
ok("a-acceleration-limit", max(abs(q) for q in aa) <= A_ACC * 1.01,
   "A accelerated at %.1f deg/s^2, MAX_ACCELERATION %.1f" % (max(abs(q) for q in aa), A_ACC))

# where each move of A ends, and which way it turned: the short way. The
# moves run into each other (a corner does not stop), so a move's first
# sample is a step past its start and its end is the next move's start.
for text, start, end in (("G1 A10 F1200", 350, 370), ("G1 A300 F2400", 370, 300),
                         ("G0 A130", 300, 130)):
    idx = of_line(text)
    a0, a1 = a[idx[0] - 1], a[idx[-1]]
    step = max(abs(a[i] - a[i - 1]) for i in idx)
    mono = all((a[i] - a[i - 1]) * (end - start) >= -1e-9 for i in idx)
    ok("short-way " + text, abs(a0 - start) <= step + 1e-6 and abs(a1 - end) <= step + 1e-6 and
       mono, "A went from %.4f to %.4f (want %g to %g, one way: %s)" % (a0, a1, start, end, mono))

# A alone: F in degrees per minute, and the path velocity column in deg/s
for text, f in (("G1 A270 F1800", 1800), ("G1 A350 F1200", 1200), ("G1 A300 F2400", 2400)):
    idx = of_line(text)
    top = speed(idx, a)
    ok("a-only-feed " + text, abs(top - f / 60.0) < 1e-3 and abs(max(v[i] for i in idx) - f / 60.0) < 1e-3,
       "A at %.4f deg/s, v %.4f, want %.4f" % (top, max(v[i] for i in idx), f / 60.0))
idx = of_line("G0 A130")
ok("a-rapid-at-max-velocity", abs(speed(idx, a) - A_VEL) < 1e-3,
   "A at %.4f deg/s" % speed(idx, a))

# X Y Z and A together: F along X Y Z, A in proportion all along the move
for text, lin, l0, l1, a0, a1, f in (("G1 X40 A90 F600", x, 0, 40, 0, 90, 600),
                                     ("G1 Y20 A180", y, 0, 20, 90, 180, 600)):
    idx = of_line(text)
    worst = max(abs((a[i] - a0) / (a1 - a0) - (lin[i] - l0) / (l1 - l0)) for i in idx)
    # the trace has 6 decimals
    ok("together " + text, worst < 1e-6, "A strays from X Y Z by %.3g of the move" % worst)
    ok("xyz-feed " + text, abs(speed(idx, lin) - f / 60.0) < 1e-3 and
       abs(speed(idx, a) - f / 60.0 * (a1 - a0) / (l1 - l0)) < 1e-3,
       "X Y Z at %.4f mm/s, A at %.4f deg/s" % (speed(idx, lin), speed(idx, a)))

# the arc with A along it: A reaches 200 in the same sample as X Y reach the end
idx = of_line("G2 X40 Y-20 I0 J-20 A200 F600")
# (a half circle about (40, 0) from (40, 20), clockwise; A from 130 to 200):
# A's share of its turn is the arc's share of its angle in every sample
worst = max(abs((a[i] - 130) / 70 - (90 - math.degrees(math.atan2(y[i], x[i] - 40))) / 180)
            for i in idx)
ok("arc-together", worst < 1e-5, "A strays from the arc by %.3g of the move" % worst)
# the actual A follows (the simulated servo)
ferr = max(abs(float(r["a_cmd"]) - float(r["a_act"])) for r in rows)
ok("a-follows", ferr < 0.05, "A's following error %.4f deg" % ferr)
