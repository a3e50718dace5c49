#!/usr/bin/python3
"""Compares the actual positions of a `cnc-run run --trace` over CAN drives
(cnc-drive-sim --config INI --axis A: the sim backend's plant per drive) with
the sim backend's trace of the same program and INI.

A drive answers SYNC k with the position it measured at that SYNC, and the
master takes that TPDO in during the next period: over CAN, row k shows the
sim's row k-1 (one servo period of transport). Under load a TPDO can come
later; then the row repeats an older actual. So, per axis, every CAN actual
must equal (within TOL mm) a sim actual of the same or an earlier row, in
order (a monotone match), and the match must reach the end of the motion.
--strict: at most 1 % of the rows may lag more than 2 periods (real hosts,
KVM). --lenient: any lag (qemu TCG: timing means nothing, values and order
still must match). Either way each axis must pass its farthest point
(lenient: within 1 % of its travel, as the one sample at the peak may be
skipped) and end where the sim ends.
Usage: compare-traces.py [--strict|--lenient] [--tol MM] SIM_CSV CAN_CSV"""
import sys

AXES = "XYZ"


def load(path):
    rows = []
    for line in open(path):
        f = line.strip().split(",")
        if len(f) < 9 or not f[0][:1].isdigit():
            continue
        rows.append([float(v) for v in f[5:8]])
    return rows


def match_axis(sim, can, j, tol):
    """Greedy monotone match (optimal for a subsequence test). Returns the
    matched sim row of every CAN row, or the first CAN row without one."""
    p, where = 0, []
    for k, row in enumerate(can):
        while p < len(sim) and p <= k and abs(sim[p][j] - row[j]) > tol:
            p += 1
        if p >= len(sim) or p > k:
            return where, k
        where.append(p)
    return where, None


def fresh(sim, can, j, k, lo, tol):
    """The newest sim row (lo..k) CAN row k may show: its lag behind row k."""
    for i in range(k, lo, -1):
        if abs(sim[i][j] - can[k][j]) <= tol:
            return i
    return lo


def peak(sim, j):
    """The row where the axis is farthest from where it started."""
    return max(range(len(sim)), key=lambda i: abs(sim[i][j] - sim[0][j]))


def compare(sim, can, tol, strict):
    errors, lags = [], []
    if not sim or not can:
        return ["empty trace"], 0
    for j, ax in enumerate(AXES):
        where, bad = match_axis(sim, can, j, tol)
        if bad is not None:
            errors.append(f"{ax}: CAN row {bad + 1} actual {can[bad][j]:.6f} matches no sim "
                          f"row up to it (tolerance {tol} mm)")
            continue
        far = sim[peak(sim, j)][j]
        # a stalled master shows only every n-th actual: the sample at the
        # very peak may be skipped, one near it may not
        far_tol = tol if strict else max(tol, 0.01 * abs(far - sim[0][j]))
        if not any(abs(row[j] - far) <= far_tol for row in can):
            errors.append(f"{ax}: CAN actuals never come within {far_tol:g} mm of "
                          f"{far:.6f}, the farthest sim actual")
        if abs(can[-1][j] - sim[-1][j]) > tol:
            errors.append(f"{ax}: last CAN actual {can[-1][j]:.6f}, sim final {sim[-1][j]:.6f}")
        lags += [k - fresh(sim, can, j, k, w, tol) for k, w in enumerate(where)]
    late = sum(1 for lag in lags if lag > 2)
    if strict and late > len(lags) // 100:
        errors.append(f"{late} of {len(lags)} axis rows lag more than 2 periods (strict)")
    return errors, max(lags) if lags else 0


def main():
    args, strict, tol = sys.argv[1:], True, 0.002
    while args and args[0].startswith("--"):
        opt = args.pop(0)
        if opt == "--tol":
            tol = float(args.pop(0))
        else:
            strict = opt == "--strict"
    sim, can = load(args[0]), load(args[1])
    errors, worst = compare(sim, can, tol, strict)
    mode = "strict" if strict else "lenient (software emulation: any lag)"
    for e in errors[:10]:
        print("trace compare:", e)
    print(f"trace compare {mode}: {len(can)} CAN rows vs {len(sim)} sim rows, tolerance "
          f"{tol} mm, worst lag {worst} periods: {'ok' if not errors else 'DIFFERENT'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
