#!/usr/bin/env python3
"""Checks a cnc-run trace's inject column against the spec that made it.

usage: check-inject.py NAME TRACE KIND ARGS...
  count TOKEN RATIO        rows with TOKEN within 4 sigma of RATIO * rows (binomial)
  at TOKEN C1,C2,...       TOKEN exactly on the rows of those cycles (row = cycle)
  const TOKEN US           every row has TOKEN=US
  uniform TOKEN LO HI      values in [LO, HI], mean and deviation of a uniform law
  normal TOKEN BOUND       values in [0, BOUND], mean BOUND/2, deviation BOUND/6
  late PERIOD_US           'late' on exactly the rows where lat + jit + io >= PERIOD
Prints one PASS/FAIL line named NAME.
"""
import csv
import math
import sys


def tokens(cell):
    out = {}
    if cell == "-":
        return out
    for t in cell.split("+"):
        k, _, v = t.partition("=")
        out[k] = float(v) if v else True
    return out


def main():
    name, trace, kind, args = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    with open(trace, newline="") as f:
        rows = [tokens(r["inject"]) for r in csv.DictReader(f)]
    n = len(rows)
    why = None
    if n < 100:
        why = "only %d rows" % n
    elif kind == "count":
        tok, ratio = args[0], float(args[1])
        k = sum(1 for r in rows if tok in r)
        mu, sd = ratio * n, math.sqrt(n * ratio * (1 - ratio))
        if abs(k - mu) > 4 * sd + 1 or k == 0:
            why = "%d of %d rows have %s, expected %.1f +- %.1f" % (k, n, tok, mu, 4 * sd)
    elif kind == "at":
        tok, want = args[0], sorted(int(c) for c in args[1].split(","))
        got = [i for i, r in enumerate(rows) if tok in r]
        if got != want:
            why = "%s on rows %s, expected %s" % (tok, got[:10], want)
    elif kind == "const":
        tok, us = args[0], float(args[1])
        bad = [i for i, r in enumerate(rows) if r.get(tok) != us]
        if bad:
            why = "%d rows without %s=%g (first: row %d)" % (len(bad), tok, us, bad[0])
    elif kind in ("uniform", "normal"):
        tok = args[0]
        lo, hi = (float(args[1]), float(args[2])) if kind == "uniform" else (0.0, float(args[1]))
        vals = [r[tok] for r in rows if tok in r]
        if len(vals) != n:
            why = "%d of %d rows have %s" % (len(vals), n, tok)
        else:
            mean = sum(vals) / n
            sd = math.sqrt(sum((v - mean) ** 2 for v in vals) / n)
            want_sd = (hi - lo) / math.sqrt(12) if kind == "uniform" else hi / 6
            if min(vals) < lo or max(vals) > hi:
                why = "%s outside [%g, %g]: %g..%g" % (tok, lo, hi, min(vals), max(vals))
            elif abs(mean - (lo + hi) / 2) > 0.03 * (hi - lo):
                why = "%s mean %.3f, expected %.3f" % (tok, mean, (lo + hi) / 2)
            elif abs(sd - want_sd) > 0.05 * want_sd:
                why = "%s deviation %.3f, expected %.3f (%s law)" % (tok, sd, want_sd, kind)
    elif kind == "late":
        period = float(args[0])
        bad = [i for i, r in enumerate(rows)
               if ("late" in r) != (r.get("lat", 0) + r.get("jit", 0) + r.get("io", 0) >= period)]
        if bad or not any("late" in r for r in rows):
            why = "late wrong on %d rows (first %s)" % (len(bad), bad[:1])
    else:
        why = "unknown check " + kind
    print(("FAIL %s: %s" % (name, why)) if why else "PASS " + name)


if __name__ == "__main__":
    main()
