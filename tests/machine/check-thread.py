#!/usr/bin/env python3
"""Checks spindle-synchronised motion from a cnc-run trace.

usage: check-thread.py TRACE PROGRAM [--pitch-scale F] [--turns-shift T]

The program's G33 (K), G76 (P) and G33.1 (K) lines give each pass's lead:
Z travels that much per spindle turn. A pass is a stretch of rows with
motion = 3 (synchronised). For each pass:
  lead     between any two rows one spindle turn apart in the part where the
           axis is locked on, |Z travel| - lead is at most 1 um (the
           catch-up after the index and a thread's braking at its end are
           outside it; they must be short: at most 3 turns each);
  phase    the locked helix, followed back to the pass's start point, meets
           it at a whole spindle turn (the index) within 1 um of lead: every
           pass of a thread starts at the same spindle angle, so cuts the
           same groove, whatever the spindle speed;
  tap      (G33.1) it comes back out locked too and ends where it started.
--pitch-scale and --turns-shift falsify the expectation (the test runs
them to show that a wrong pitch or a lost index fails).
Prints PASS/FAIL lines (name, then why)."""
import csv
import re
import sys

TOL = 1e-3      # mm: 1 um of lead per turn
MAX_OFF = 3.0   # turns of catch-up or braking a pass may take


def ok(name, cond, why):
    print(("PASS " if cond else "FAIL ") + name + ("" if cond else ": " + why))
    return cond


def leads(program):
    out = {}
    with open(program) as f:
        for no, text in enumerate(f, 1):
            code = re.sub(r"\(.*?\)", "", text).upper()
            m = re.search(r"G33\.1.*?K([-+0-9.]+)", code) or re.search(r"G33\b.*?K([-+0-9.]+)", code)
            kind = "tap" if "G33.1" in code else "thread"
            if not m:
                m = re.search(r"G76.*?P([-+0-9.]+)", code)
            if m:
                out[no] = (abs(float(m.group(1))), kind)
    return out


def passes(rows):
    cur = []
    for i, r in enumerate(rows):
        if r["motion"] == "3":
            cur.append(i)
        elif cur:
            yield cur
            cur = []
    if cur:
        yield cur


def locked_stretch(z, u, lead):
    """Longest run of rows i whose turn ahead (u + 1, interpolated) keeps
    |dz| - lead within TOL; returns (first, last) row index or None."""
    best, start, j = None, None, 0
    n = len(z)
    for i in range(n):
        j = max(j, i)
        while j < n - 1 and abs(u[j] - u[i]) < 1.0:
            j += 1
        good = False
        if j > i and abs(u[j] - u[i]) >= 1.0 and abs(u[j - 1] - u[i]) < 1.0:
            f = (1.0 - abs(u[j - 1] - u[i])) / (abs(u[j] - u[i]) - abs(u[j - 1] - u[i]))
            zj = z[j - 1] + f * (z[j] - z[j - 1])
            good = abs(abs(zj - z[i]) - lead) <= TOL
        if good and start is None:
            start = i
        if (not good or i == n - 1) and start is not None:
            end = i if good else i - 1
            if best is None or end - start > best[1] - best[0]:
                best = (start, end)
            start = None
    return best


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    scale, shift = 1.0, 0.0
    if "--pitch-scale" in argv:
        scale = float(argv[argv.index("--pitch-scale") + 1])
    if "--turns-shift" in argv:
        shift = float(argv[argv.index("--turns-shift") + 1])
    with open(argv[1]) as f:
        rows = list(csv.DictReader(f))
    table = leads(argv[2])
    good = ok("trace-columns", rows and "spindle_turns" in rows[0], "no spindle_turns column")
    if not good:
        return 1
    seen = 0
    worst_lead, worst_phase = 0.0, 0.0
    for k, p in enumerate(passes(rows)):
        line = int(rows[p[0]]["line"])
        if line not in table:
            good &= ok("pass-%d-line" % k, False, "line %d has no G33/G76/G33.1" % line)
            continue
        lead, kind = table[line]
        lead *= scale
        seen += 1
        before = rows[p[0] - 1]          # at rest at the pass's start
        z0 = float(before["z_cmd"])
        z = [float(rows[i]["z_cmd"]) for i in p]
        u = [float(rows[i]["spindle_turns"]) + shift * (i - p[0] > 0) for i in p]
        name = "pass-%d(line %d)" % (k, line)
        if kind == "tap":
            # in and out: each way locked; the end where it began
            bottom = min(range(len(z)), key=lambda i: z[i])
            for way, (a, b) in (("in", (0, bottom)), ("out", (bottom, len(z)))):
                s = locked_stretch(z[a:b], u[a:b], lead)
                turns = abs(u[b - 1] - u[a])
                span = (abs(u[a + s[1]] - u[a + s[0]]) + 1) if s else 0
                good &= ok(name + "-" + way + "-lead", s is not None and span >= turns - 2 * MAX_OFF,
                           "locked over %.2f of %.2f turns" % (span, turns))
            end = float(rows[p[-1] + 1]["z_cmd"]) if p[-1] + 1 < len(rows) else z[-1]
            good &= ok(name + "-back", abs(end - z0) < 1e-6, "ends at Z%.6f, began at Z%.6f" % (end, z0))
            continue
        s = locked_stretch(z, u, lead)
        turns = abs(u[-1] - u[0])
        span = (abs(u[s[1]] - u[s[0]]) + 1) if s else 0
        good &= ok(name + "-lead", s is not None and span >= turns - 2 * MAX_OFF,
                   "locked over %.2f of %.2f turns within %.1f um per turn" % (span, turns, TOL * 1e3))
        if s is None:
            continue
        # the lead over the locked part as a whole, per turn
        dz, du = abs(z[s[1]] - z[s[0]]), abs(u[s[1]] - u[s[0]])
        if du > 0:
            worst_lead = max(worst_lead, abs(dz / du - lead))
        # the helix through the locked part, back at the start point: at
        # which spindle angle (in turns, 0 = the index) does it meet z0?
        i = (s[0] + s[1]) // 2
        at = u[i] - abs(z[i] - z0) / lead
        phase = at - round(at)
        worst_phase = max(worst_phase, abs(phase))
        good &= ok(name + "-phase", abs(phase) * lead <= TOL,
                   "starts %.4f turns (%.1f deg, %.1f um of lead) away from the index"
                   % (phase, phase * 360, phase * lead * 1e3))
    good &= ok("passes", seen > 0, "no synchronised pass in the trace")
    print("# %d passes, worst lead error over a locked part %.2e mm per turn, worst phase %.2e turns"
          % (seen, worst_lead, worst_phase))
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
