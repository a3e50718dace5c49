#!/usr/bin/python3
"""latency.py OUT.json [--seconds S] [--build DIR] [--program PROG]

Wake-up latency of a 1 ms SCHED_FIFO 90 loop under the same background load,
one after the other in one run: first `cyclictest -m -S -p 90 -i 1000`, then
ncpar's position loop (`cnc-run run PROG --for S`), while a loop of `cnc-run
parse` interprets the 1M-block program in the background the whole time.
Both histograms have 1 us bins up to 1 ms (beyond: overflow). The loop's
histogram comes from the latency sidecar that `cnc-run run --plot` writes beside
its --trace (NCPAR_PLOT_SCRIPT points the plot step at a no-op).

Runs on the host and, unchanged, inside the RT guest (tools/rtvm/run); the
label says where, so that emulated (TCG) figures are never taken for RT ones."""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
HIST_US = 1000


def where():
    accel = os.environ.get("RTVM_ACCEL")
    rt = open("/sys/kernel/realtime").read().strip() == "1" \
        if os.path.exists("/sys/kernel/realtime") else False
    if accel == "tcg":
        return "tcg", "PREEMPT_RT guest under TCG software emulation: NOT latency figures"
    if accel == "kvm":
        return "kvm", "PREEMPT_RT guest under KVM: latency of this host's virtualization"
    if rt:
        return "rt", "PREEMPT_RT host"
    return "stock", "stock (non-PREEMPT_RT) kernel: not an RT figure"


def rel(path):
    """Paths inside the tree as the commands would be typed at its top."""
    r = os.path.relpath(path, ROOT)
    return path if r.startswith("..") else r


def start_background(cnc, prog):
    """A shell loop of `cnc-run parse PROG`; returns the Popen of the shell."""
    cmd = "while :; do %s parse %s --canon /dev/null || exit 1; done" % (rel(cnc), rel(prog))
    return subprocess.Popen(["/bin/sh", "-c", cmd], stdout=subprocess.DEVNULL, cwd=ROOT,
                            stderr=subprocess.DEVNULL, start_new_session=True), cmd


def stop_background(bg):
    # the loop's shell leads its own session: signal exactly that group
    try:
        os.killpg(bg.pid, 15)
    except ProcessLookupError:
        pass
    bg.wait()


def run_cyclictest(seconds):
    loops = int(seconds * 1000)
    cmd = ["cyclictest", "-m", "-S", "-p", "90", "-i", "1000", "-l", str(loops),
           "-h", str(HIST_US), "-q"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=seconds * 3 + 60)
    if p.returncode != 0:
        return {"cmd": " ".join(cmd), "error": (p.stderr or p.stdout).strip()[-300:]}
    hist, per_thread = [0] * HIST_US, {}
    for line in p.stdout.splitlines():
        if re.match(r"^\d{6}", line):
            cols = line.split()
            b = int(cols[0])
            if b < HIST_US:
                hist[b] += sum(int(c) for c in cols[1:])
        elif line.startswith("# "):
            key, _, vals = line[2:].partition(":")
            nums = [int(v) for v in vals.split() if v.isdigit()]
            per_thread.setdefault(key.strip(), nums)   # first line of a key: the counts
    over = sum(per_thread.get("Histogram Overflows", []))
    cycles = sum(per_thread.get("Total", [])) + over   # Total leaves the overflows out
    mins, maxs, avgs = (per_thread.get(k, []) for k in
                        ("Min Latencies", "Max Latencies", "Avg Latencies"))
    avg = sum(a * c for a, c in zip(avgs, per_thread.get("Total", []))) / cycles \
        if cycles and avgs else None
    return {"cmd": " ".join(cmd), "cycles": cycles, "hist": hist, "overflow": over,
            "min_us": min(mins) if mins else None, "max_us": max(maxs) if maxs else None,
            "avg_us": avg, "threads": len(maxs), "per_thread_max_us": maxs}


def run_loop(cnc, prog, seconds, config):
    tmp = tempfile.mkdtemp(prefix="bench-lat.", dir=os.path.join(ROOT, "bench", "out"))
    noplot = os.path.join(tmp, "noplot.py")
    with open(noplot, "w") as f:
        f.write("# no-op stand-in for tools/plot-trace.py: only the sidecar is wanted\n")
    trace = os.path.join(tmp, "trace.csv")
    cmd = [cnc, "run", prog, "--config", config, "--for", str(seconds),
           "--trace", trace, "--plot", os.path.join(tmp, "unused.png")]
    env = dict(os.environ, NCPAR_PLOT_SCRIPT=noplot)
    p = subprocess.run(cmd, capture_output=True, text=True, env=env,
                       timeout=seconds * 4 + 120)
    out = {"cmd": " ".join(rel(c) for c in cmd[:7]), "summary": p.stderr.strip().splitlines()}
    side = trace + ".latency.csv"
    if p.returncode not in (0,) and not os.path.exists(side):
        out["error"] = "exit %d: %s" % (p.returncode, p.stderr.strip()[-300:])
        shutil.rmtree(tmp, ignore_errors=True)
        return out
    hist, over = [0] * HIST_US, 0
    with open(side) as f:
        next(f)
        for line in f:
            k, v = line.strip().split(",")
            if k.startswith(">="):
                over += int(v)
            elif int(k) < HIST_US:
                hist[int(k)] += int(v)
    m = re.search(r"loop latency: min ([\d.]+) us, avg ([\d.]+) us, max ([\d.]+) us over (\d+)",
                  p.stderr)
    if m:
        out.update(min_us=float(m.group(1)), avg_us=float(m.group(2)),
                   max_us=float(m.group(3)), cycles=int(m.group(4)))
    miss = re.search(r"deadline misses (\d+)", p.stderr)
    out.update(hist=hist, overflow=over, misses=int(miss.group(1)) if miss else None,
               fifo="position loop SCHED_FIFO" in p.stderr, exit=p.returncode)
    shutil.rmtree(tmp, ignore_errors=True)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--program", default=os.path.join(ROOT, "bench/out/cam-1000000.ngc"))
    ap.add_argument("--config", default=os.path.join(ROOT, "rt-config/sim-3axis.ini"))
    o = ap.parse_args()
    cnc = os.path.join(o.build, "cnc-run")
    kind, label = where()
    res = {"where": kind, "label": label, "seconds": o.seconds,
           "kernel": os.uname().release + " " + os.uname().version}
    if not shutil.which("cyclictest"):
        res["cyclictest"] = {"error": "cyclictest not installed (apt-get install rt-tests)"}
    bg, bg_cmd = start_background(cnc, o.program)
    res["background"] = bg_cmd
    try:
        time.sleep(1)    # let the background loop reach its steady state
        if "cyclictest" not in res:
            res["cyclictest"] = run_cyclictest(o.seconds)
        res["ncpar"] = run_loop(cnc, o.program, o.seconds, o.config)
    finally:
        stop_background(bg)
    with open(o.out, "w") as f:
        json.dump(res, f)
    for k in ("cyclictest", "ncpar"):
        r = res[k]
        print("%-10s %s" % (k, r.get("error") or "max %s us, avg %s us over %s cycles" % (
            r.get("max_us"), r.get("avg_us"), r.get("cycles"))), file=sys.stderr)


if __name__ == "__main__":
    main()
