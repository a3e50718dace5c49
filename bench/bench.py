#!/usr/bin/python3
"""bench.py OUTDIR: the measurements of `make bench`, into OUTDIR/data.json.

1. Table 3 of the interpreter-pipeline paper: every configuration (serial, DETn, ATTn; n = 2, 4, 8;
   normal and SCHED_FIFO 90) RUNS times on part998 and RUNS_BIG times on the
   1M-block program (build/bench/table3: many runs in one process), the runs of
   each configuration split into rounds that visit every configuration.
2. Against LinuxCNC: process wall time of `rs274 -g` and of `cnc-run parse`
   (serial and the best parallel configuration of part 1), interleaved, on
   part998, the 1M-block program and the three largest ncfiles rs274 accepts;
   each program's output checked against rs274's (tests/tools/compare-rs274).
3. Loop latency (bench/latency.py): cyclictest and the position loop under a
   background parse loop; in the RT guest too when it boots (BENCH_RTVM=0: never).

Environment (defaults): RUNS (500), RUNS_BIG (20), ROUNDS (5), ROUNDS_BIG (4),
T3_MAX_S (30) and T3_MAX_S_BIG (25): the most seconds of timed runs one
configuration gets over all rounds, RS_REPS (5), RS_REPS_BIG (3), LAT_SECONDS
(60), GUEST_SECONDS (20), BLOCKS (1000000), BUDGET_S (1080): the guest is
skipped when less than it needs is left of this budget (20 min - 2)."""
import glob
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TOOLS = os.path.join(ROOT, "tests", "tools")
NCFILES = "/usr/share/linuxcnc/ncfiles"
TOOL_TABLE = "rt-config/tools.tbl"
DEFAULT_TABLE = "/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/simpockets.tbl"
CONFIGS = [b + s for s in ("", "-fifo")
           for b in ("serial", "det2", "att2", "det4", "att4", "det8", "att8",
                     "det2-inline", "att2-inline", "det2-j0", "att2-j0")]
# On a 4-CPU host the paper's own ATT8 map (LEX3 beside the feeder on CPU0, Table 2)
# differs from the scaled one and runs as an extra row; its ATT4 map is the scaled one.
PAPER4 = ["paper4-att8", "paper4-att8-fifo"]


def map_path(maps, cfg):
    if cfg.startswith("paper4-"):
        return os.path.join(ROOT, "rt-config", "paper4", cfg[len("paper4-"):] + ".ini")
    return os.path.join(maps, cfg + ".ini")


def env_num(name, default):
    v = os.environ.get(name)
    return type(default)(v) if v else default


T0 = time.time()


def log(msg):
    print("bench: [%4d s] %s" % (time.time() - T0, msg), file=sys.stderr, flush=True)


def sh(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, shell=True).stdout.strip()
    except OSError:
        return ""


def lscpu_summary():
    """One line from lscpu: model, family/model, CPUs as sockets x cores x threads,
    NUMA nodes, whether a hypervisor runs it; and the memory. "" without lscpu."""
    f = {}
    for line in sh("LC_ALL=C lscpu").splitlines():
        k, _, v = line.partition(":")
        f[k.strip()] = v.strip()
    if not f.get("Model name"):
        return ""
    mem = sh("awk '/^MemTotal/ {printf \"%.1f\", $2 / 1048576}' /proc/meminfo")
    return "%s (family %s, model %s), %s CPUs = %s socket(s) x %s cores x %s thread(s) per core, " \
        "%s NUMA node(s), %s; %s GB RAM" % (
            f["Model name"], f.get("CPU family", "?"), f.get("Model", "?"),
            f.get("CPU(s)", "?"), f.get("Socket(s)", "?"), f.get("Core(s) per socket", "?"),
            f.get("Thread(s) per core", "?"), f.get("NUMA node(s)", "?"),
            "virtual machine (%s)" % f["Hypervisor vendor"] if f.get("Hypervisor vendor")
            else "virtual machine" if " hypervisor " in " %s " % f.get("Flags", "")
            else "bare metal", mem or "?")


def machine_facts():
    model = sh("grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-").strip()
    return {
        "date": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
        "kernel": platform.release(), "kernel_version": platform.version(),
        "preempt_rt": sh("cat /sys/kernel/realtime 2>/dev/null") == "1",
        "cpu_model": model, "lscpu": lscpu_summary(), "cpus": os.cpu_count(),
        "cpus_allowed": len(os.sched_getaffinity(0)),
        "loadavg_start": open("/proc/loadavg").read().split()[:3],
        "rt_runtime_us": sh("cat /proc/sys/kernel/sched_rt_runtime_us"),
        "uid": os.getuid(),
        "git": sh("git -C %s rev-parse --short HEAD" % ROOT),
        "git_dirty": bool(sh("git -C %s status --porcelain -- src include" % ROOT)),
        "rs274": sh("dpkg-query -W -f='${Version}' linuxcnc-uspace 2>/dev/null"),
        "rt_tests": sh("dpkg-query -W -f='${Version}' rt-tests 2>/dev/null"),
    }


# ---- 1. Table 3 ------------------------------------------------------------------

def parse_driver(text):
    out = {"runs": [], "warnings": [], "stopped": None}
    for line in text.splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "run" and len(f) >= 4:
            out["runs"].append([float(x) for x in f[2:5]])
        elif f[0] == "hash" and len(f) >= 6:
            out.update(hash=f[1], blocks=int(f[3]), commands=int(f[5]))
        elif f[0] == "warning":
            out["warnings"].append(line[8:])
        elif f[0] == "stopped":
            out["stopped"] = int(f[1])
    return out


def run_driver(cmd, limit_s):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=limit_s)
    except subprocess.TimeoutExpired as e:
        # a hung configuration must not stop the suite: its row says so
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else e.stdout
        p = subprocess.CompletedProcess(cmd, 124, out or "", "timed out after %d s" % limit_s)
    return p


def table3(build, maps, prog, runs, max_s, chunks, raw):
    """Every configuration `runs` times, in `chunks` rounds that each run every
    configuration once (runs/chunks each, one process per round and configuration),
    so that a load change during the suite spreads over all of them alike."""
    configs = CONFIGS + (PAPER4 if len(os.sched_getaffinity(0)) == 4 else [])
    rows = {c: {"runs": [], "warnings": [], "stopped": None, "exit": 0} for c in configs}
    chunks = max(1, min(chunks, runs))
    for k in range(chunks):
        n = runs // chunks + (1 if k < runs % chunks else 0)
        for cfg in configs:
            cmd = [os.path.join(build, "bench", "table3"), prog, map_path(maps, cfg), str(n),
                   "--tool-table", TOOL_TABLE,
                   "--max-seconds", "%g" % (max_s / chunks)]
            t0 = time.time()
            p = run_driver(cmd, max_s / chunks + 120)
            name = "table3-%s-%s.txt" % (os.path.basename(prog), cfg)
            with open(os.path.join(raw, name), "a") as f:
                f.write("$ %s\n%s%s" % (" ".join(cmd), p.stdout, p.stderr))
            got, r = parse_driver(p.stdout), rows[cfg]
            r["runs"] += got["runs"]
            r["warnings"] = sorted(set(r["warnings"] + got["warnings"]))
            for key in ("hash", "blocks", "commands"):
                if key in got:
                    if r.get(key, got[key]) != got[key]:
                        r["error"] = "%s differs between rounds" % key
                    r[key] = got[key]
            if got["stopped"] is not None:
                r["stopped"] = (r["stopped"] or 0) + 1
            if p.returncode:
                r["exit"] = p.returncode
                r["error"] = p.stderr.strip()[-300:]
            r["cmd"] = " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c
                                for c in cmd)
            log("%-12s round %d/%d %-12s %4d runs in %5.1f s%s" % (
                os.path.basename(prog), k + 1, chunks, cfg, len(got["runs"]),
                time.time() - t0, "  EXIT %d" % p.returncode if p.returncode else ""))
    return rows


def mean_of(row):
    return statistics.fmean(r[0] for r in row["runs"]) if row.get("runs") else float("inf")


def best_parallel(rows):
    par = [c for c in rows if not c.startswith("serial") and rows[c].get("runs")]
    return min(par, key=lambda c: mean_of(rows[c])) if par else None


# ---- 2. rs274 ---------------------------------------------------------------------

def read_name_map(path):
    out = {}
    if os.path.exists(path):
        for line in open(path, encoding="utf-8"):
            line = line.strip()
            if line and not line.startswith("#"):
                k, _, v = line.partition(" ")
                out[k] = v.strip()
    return out


def largest_accepted(n):
    skips = read_name_map(os.path.join(TOOLS, "rs274-skip.txt"))
    tables = read_name_map(os.path.join(TOOLS, "rs274-tables.txt"))
    progs = sorted(glob.glob(os.path.join(NCFILES, "*.ngc")), key=os.path.getsize, reverse=True)
    picked = []
    for p in progs:
        if os.path.basename(p) in skips:
            continue
        tbl = tables.get(os.path.basename(p), DEFAULT_TABLE)
        rc = subprocess.run([os.path.join(TOOLS, "rs274-canon"), p, tbl], capture_output=True,
                            timeout=300).returncode
        if rc == 0:
            picked.append((os.path.basename(p), p, tbl))
        if len(picked) == n:
            break
    return picked


STATS = re.compile(r"(\d+) blocks,.*?([\d.]+) ms(?: \(([\d.]+) ms start-up\))?")


def timed(cmd, cwd=None, env=None):
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=env,
                           stdin=subprocess.DEVNULL, timeout=300)
    except subprocess.TimeoutExpired:
        p = subprocess.CompletedProcess(cmd, 124, "", "timed out after 300 s")
    return time.perf_counter() - t0, p


def run_rs274(prog, tbl, tmp):
    env = dict(os.environ, HOME=tmp)
    return timed(["rs274", "-g", "-t", tbl, prog, os.path.join(tmp, "rs274.out")], tmp, env)


def run_ours(build, prog, tbl, canon, config=None):
    """config None: the serial reference."""
    cmd = [os.path.join(build, "cnc-run"), "parse", prog, "--tool-table", tbl, "--canon", canon,
           "--stats"]
    cmd += ["--config", config] if config else ["--mode", "serial"]
    dt, p = timed(cmd, ROOT)
    m = STATS.search(p.stderr)
    inner = float(m.group(2)) / 1e3 if m else None
    blocks = int(m.group(1)) if m else None
    return dt, p, inner, blocks


def compare_rs274(build, prog, tbl):
    p = subprocess.run([os.path.join(TOOLS, "compare-rs274"), "--bin",
                        os.path.join(build, "cnc-run"), "--tool-table", tbl, "--timeout", "600",
                        prog], capture_output=True, text=True, cwd=ROOT)
    line = (p.stdout.strip().splitlines() or ["FAIL (no output)"])[-1]
    return line.replace(prog, os.path.basename(prog))


def versus_rs274(build, maps, programs, best, reps_small, reps_big):
    out = []
    tmp = tempfile.mkdtemp(prefix="bench-rs274.", dir=os.path.join(ROOT, "bench", "out"))
    try:
        for name, prog, tbl, key in programs:
            tbl_abs = os.path.join(ROOT, tbl) if not tbl.startswith("/") else tbl
            prog_abs = os.path.join(ROOT, prog) if not prog.startswith("/") else prog
            cfg = best.get(key)
            config = map_path(maps, cfg) if cfg else None
            reps = reps_big if os.path.getsize(prog_abs) > 5e6 else reps_small
            t = {"rs274": [], "serial": [], "parallel": [], "serial_inner": [],
                 "parallel_inner": []}
            blocks, errors = None, []
            for _ in range(reps):
                dt, p = run_rs274(prog_abs, tbl_abs, tmp)
                if p.returncode:
                    errors.append("rs274 exit %d" % p.returncode)
                t["rs274"].append(dt)
                dt, p, inner, blocks = run_ours(build, prog_abs, tbl_abs,
                                                os.path.join(tmp, "serial.canon"))
                t["serial"].append(dt)
                t["serial_inner"].append(inner)
                if p.returncode:
                    errors.append("serial exit %d" % p.returncode)
                if config:
                    dt, p, inner, _ = run_ours(build, prog_abs, tbl_abs,
                                               os.path.join(tmp, "par.canon"), config)
                    t["parallel"].append(dt)
                    t["parallel_inner"].append(inner)
                    if p.returncode:
                        errors.append("parallel exit %d" % p.returncode)
            same = None
            if config:
                same = subprocess.run(["cmp", "-s", os.path.join(tmp, "serial.canon"),
                                       os.path.join(tmp, "par.canon")]).returncode == 0
            log("rs274 %-28s %d reps timed; checking its output against rs274" % (name, reps))
            out.append({"name": name, "prog": prog, "table": tbl, "reps": reps,
                        "blocks": blocks, "parallel_cfg": cfg, "times": t,
                        "parallel_equals_serial": same, "errors": sorted(set(errors)),
                        "check": compare_rs274(build, prog_abs, tbl_abs)})
        # the fixed cost of starting each program, for reading the small programs
        empty = os.path.join(tmp, "empty.ngc")
        with open(empty, "w") as f:
            f.write("G0 X1\nM2\n")
        floor = {"rs274": min(run_rs274(empty, os.path.join(ROOT, TOOL_TABLE), tmp)[0]
                              for _ in range(5)),
                 "ours": min(run_ours(build, empty, os.path.join(ROOT, TOOL_TABLE),
                                      "/dev/null")[0] for _ in range(5))}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out, floor


# ---- 3. latency in the RT guest -----------------------------------------------------

def guest_latency(out_json, seconds, left_s):
    if os.environ.get("BENCH_RTVM", "1") == "0":
        return {"skipped": "BENCH_RTVM=0"}
    need = seconds * 3 + 100   # two boots, the background loop, both loops, emulation
    if left_s < need:
        return {"skipped": "not enough of the time budget left (%d s, needs about %d s)"
                % (left_s, need)}
    avail = subprocess.run([os.path.join(ROOT, "tools/rtvm/available")], capture_output=True,
                           text=True, cwd=ROOT)
    if avail.returncode:
        return {"skipped": "RT guest not available: " + avail.stdout.strip()[-200:]}
    # the guest sees only the project directory (its /tmp is empty): write inside it
    inside = os.path.join(ROOT, "bench", "out", "latency-guest.json")
    if os.path.exists(inside):
        os.unlink(inside)
    rel = os.path.relpath(inside, ROOT)
    # the 1M-block program is too slow to pre-check under emulation: part998 in its place
    cmd = ["tools/rtvm/run", "--timeout", str(int(min(seconds * 6 + 240, left_s - 20))), "--",
           "bench/latency.py", rel, "--seconds", str(seconds),
           "--program", "ncprograms/part998.ngc"]
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if os.path.exists(inside):
        shutil.move(inside, out_json)
    if p.returncode or not os.path.exists(out_json):
        return {"skipped": "guest run failed (exit %d): %s" % (p.returncode,
                                                             p.stderr.strip()[-200:]),
                "cmd": " ".join(cmd)}
    with open(out_json) as f:
        res = json.load(f)
    res["cmd"] = " ".join(cmd)
    res["guest_banner"] = [l for l in (p.stdout + p.stderr).splitlines() if "guest" in l][:3]
    return res


def main():
    outdir = sys.argv[1]
    build = os.path.abspath(sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "build"))
    raw = os.path.join(outdir, "raw")
    maps = os.path.join(outdir, "maps")
    os.makedirs(raw, exist_ok=True)
    t_start = time.time()
    data = {"facts": machine_facts(), "env": {}}
    for k, d in (("RUNS", 500), ("RUNS_BIG", 20), ("ROUNDS", 5), ("ROUNDS_BIG", 4),
                 ("T3_MAX_S", 30.0),
                 ("T3_MAX_S_BIG", 25.0),
                 ("RS_REPS", 5), ("RS_REPS_BIG", 3), ("LAT_SECONDS", 60.0),
                 ("GUEST_SECONDS", 20.0), ("BLOCKS", 1000000), ("BUDGET_S", 1080)):
        data["env"][k] = env_num(k, d)
    E = data["env"]
    subprocess.run([os.path.join(HERE, "gen-maps.py"), maps], check=True)
    big = "bench/out/cam-%d.ngc" % E["BLOCKS"]
    if not os.path.exists(os.path.join(ROOT, big)):
        with open(os.path.join(ROOT, big), "w") as f:
            subprocess.run(["/usr/bin/python3", os.path.join(HERE, "gen-cam.py"),
                            str(E["BLOCKS"])], stdout=f, check=True)
    data["programs"] = {"part998": "ncprograms/part998.ngc", "big": big}

    log("Table 3: %d runs per configuration on part998" % E["RUNS"])
    data["table3_part998"] = table3(build, maps, data["programs"]["part998"], E["RUNS"],
                                    E["T3_MAX_S"], E["ROUNDS"], raw)
    log("Table 3: %d runs per configuration on %s" % (E["RUNS_BIG"], big))
    data["table3_big"] = table3(build, maps, big, E["RUNS_BIG"], E["T3_MAX_S_BIG"],
                                E["ROUNDS_BIG"], raw)

    best = {"part998": best_parallel(data["table3_part998"]),
            "big": best_parallel(data["table3_big"])}
    programs = [("part998.ngc", data["programs"]["part998"], TOOL_TABLE, "part998"),
                (os.path.basename(big), big, TOOL_TABLE, "big")]
    programs += [(n, p, t, "big") for n, p, t in largest_accepted(3)]
    log("rs274 comparison on %s" % ", ".join(p[0] for p in programs))
    data["rs274"], data["startup_floor"] = versus_rs274(build, maps, programs, best,
                                                        E["RS_REPS"], E["RS_REPS_BIG"])

    log("latency: cyclictest, then the position loop, %g s each" % E["LAT_SECONDS"])
    lat_json = os.path.join(outdir, "latency-host.json")
    subprocess.run([os.path.join(HERE, "latency.py"), lat_json, "--seconds",
                    str(E["LAT_SECONDS"]), "--build", build, "--program",
                    os.path.join(ROOT, big)], check=False)
    data["latency"] = json.load(open(lat_json)) if os.path.exists(lat_json) else {}
    log("latency in the RT guest (if it boots)")
    data["latency_guest"] = guest_latency(os.path.join(outdir, "latency-guest.json"),
                                          E["GUEST_SECONDS"],
                                          E["BUDGET_S"] - (time.time() - t_start))
    data["facts"]["loadavg_end"] = open("/proc/loadavg").read().split()[:3]
    data["facts"]["duration_s"] = round(time.time() - t_start)
    with open(os.path.join(outdir, "data.json"), "w") as f:
        json.dump(data, f)
    log("done in %d s" % data["facts"]["duration_s"])


if __name__ == "__main__":
    main()
