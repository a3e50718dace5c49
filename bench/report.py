#!/usr/bin/python3
"""report.py DATA.json RESULTS.md: writes the `make bench` sections of RESULTS.md
and the PNGs beside it from one run's measurements (bench/bench.py).

Sections of an existing RESULTS.md that other scripts own (bench-motion,
bench-parse) are kept verbatim after ours, each with its own date."""
import json
import math
import os
import statistics
import sys

sys.dont_write_bytecode = True   # plots.py sits beside us: no __pycache__ in bench/
import plots  # noqa: E402

OURS = "<!-- make bench -->"      # marks the start and end of the generated part
PAPER_GAIN = {"det4": 1.914, "att4": 3.524, "det8": 0.995, "att8": 1.3245,
              "det4-fifo": 4.205, "att4-fifo": 4.225, "det8-fifo": 2.621,
              "att8-fifo": 4.0498}
PAPER_SERIAL_MS = {"": 9.265, "-fifo": 10.643}
BASES = ("serial", "det2", "att2", "det4", "att4", "det8", "att8", "det2-inline",
         "att2-inline", "det2-j0", "att2-j0")


def bases(rows):
    """Our configurations, then the paper's 4-CPU map where it ran (4-CPU hosts)."""
    return BASES + tuple(b for b in ("paper4-att8",) if b in rows)


def label(cfg):
    if cfg.startswith("paper4-"):
        return label(cfg[len("paper4-"):]) + " (paper's map)"
    base, fifo = cfg.replace("-fifo", ""), cfg.endswith("-fifo")
    pre = "Prio 90." if fifo else "Non RT."
    if base == "serial":
        return pre + " Serial"
    if base.endswith("-inline"):
        return "%s %s 2 Threads, inline output (ours)" % (pre, base[:3].capitalize())
    if base.endswith("-j0"):
        return "%s %s 2 Threads, analyzer lexes (ours)" % (pre, base[:3].capitalize())
    return "%s %s %s Threads" % (pre, base[:3].capitalize(), base[3:])


def stats(xs):
    if not xs:
        return None
    return {"n": len(xs), "mean": statistics.fmean(xs), "min": min(xs), "max": max(xs),
            "sd": statistics.stdev(xs) if len(xs) > 1 else 0.0}


def series(row, pool):
    """Run times in ms: wall (thread creation incl.), or the pre-started pool's run
    of the same program (wall - setup from drivers that had no pool)."""
    runs = row.get("runs", [])
    if not pool:
        return [r[0] for r in runs]
    return [r[2] if len(r) > 2 else r[0] - r[1] for r in runs]


def fmt(x, nd=3):
    return "-" if x is None else ("%.*f" % (nd, x))


def gains(rows, cfg, pool):
    """Gain over the serial run of the same priority, and the gains of the two
    halves of the runs (how far it moves within one run)."""
    ser = series(rows.get("serial" + ("-fifo" if cfg.endswith("-fifo") else ""), {}), pool)
    own = series(rows.get(cfg, {}), pool)
    if not ser or not own:
        return None, None
    g = statistics.fmean(ser) / statistics.fmean(own)
    h1 = statistics.fmean(ser[:len(ser) // 2] or ser) / statistics.fmean(own[:len(own) // 2] or own)
    h2 = statistics.fmean(ser[len(ser) // 2:]) / statistics.fmean(own[len(own) // 2:])
    return g, (min(h1, h2), max(h1, h2))


def table3_md(rows, pool):
    out = ["| configuration | runs | mean (ms) | min (ms) | max (ms) | σ (ms) | gain | "
           "gain, 1st/2nd half | paper gain |", "|---|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for fifo in ("", "-fifo"):
        for base in bases(rows):
            cfg = base + fifo
            row = rows.get(cfg, {})
            s = stats(series(row, pool))
            if not s:
                out.append("| %s | 0 | failed: %s | | | | | | |" % (
                    label(cfg), row.get("error", "no runs").replace("|", "/")[:80]))
                continue
            g, halves = gains(rows, cfg, pool)
            is_serial = base == "serial"
            out.append("| %s | %d%s | %s | %s | %s | %s | %s | %s | %s |" % (
                label(cfg), s["n"], "*" if row.get("stopped") else "", fmt(s["mean"]),
                fmt(s["min"]), fmt(s["max"]), fmt(s["sd"]),
                "-" if is_serial else fmt(g),
                "-" if is_serial or not halves else "%s / %s" % (fmt(halves[0]), fmt(halves[1])),
                ("(mean %.3f ms)" % PAPER_SERIAL_MS[fifo]) if is_serial
                else fmt(PAPER_GAIN.get(cfg.replace("paper4-", "")))))
    return out


def table3_text(rows, pool_rows_note, prog_name):
    """What the table shows, computed from it: no claim without its number."""
    par = [c for c in rows if not c.startswith("serial") and rows[c].get("runs")]
    if not par or not rows.get("serial", {}).get("runs"):
        return ["No complete data: see the failed rows."]
    lines = []
    for pool in (False, True):
        g = {c: gains(rows, c, pool)[0] for c in par}
        best = max(g, key=g.get)
        faster = sorted(c for c in g if g[c] > 1.0)
        what = "without thread creation" if pool else "with thread creation"
        lines.append("%s %s: the best configuration is %s (gain %.2f); %s." % (
            prog_name, what, label(best), g[best],
            "%d of %d parallel configurations beat the serial run of their priority (%s)"
            % (len(faster), len(g), ", ".join(faster)) if faster
            else "no parallel configuration beats the serial run of its priority"))
    ser = stats(series(rows["serial"], False))
    share = [statistics.fmean(r[1] for r in rows[c]["runs"]) / statistics.fmean(
        r[0] for r in rows[c]["runs"]) for c in par]
    lines.append("Our serial reference takes %.3f ms here%s. Ring allocation and thread "
                 "creation (%s threads) are %.0f-%.0f %% of the parallel runs' mean time on "
                 "this program." % (
                     ser["mean"], " (the paper's, on its 998-block program: 9.265 ms)"
                     if "998" in prog_name else "", pool_rows_note, 100 * min(share),
                     100 * max(share)))
    return lines


def plots_table3(data, outdir):
    small, big = data["table3_part998"], data["table3_big"]
    bigname = os.path.basename(data["programs"]["big"])
    for fifo in ("", "-fifo"):
        for base in bases(small):
            cfg = base + fifo
            groups = [(name, [("with thread\ncreation", series(rows.get(cfg, {}), False)),
                              ("without", series(rows.get(cfg, {}), True))])
                      for name, rows in (("part998.ngc", small), (bigname, big))]
            plots.box_png(os.path.join(outdir, "box-%s.png" % cfg),
                          "%s (%s)" % (label(cfg), cfg), groups)
    for rows, name, png in ((small, "part998.ngc", "table3-part998.png"),
                            (big, bigname, "table3-big.png")):
        boxes = [(b + f, series(rows[b + f], False)) for f in ("", "-fifo")
                 for b in bases(rows) if rows.get(b + f, {}).get("runs")]
        plots.overview_png(os.path.join(outdir, png),
                           "%s: run times per configuration" % name, boxes)


# ---- rs274 ---------------------------------------------------------------------------

def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def rs274_md(data):
    out = ["| program | blocks | rs274 (s) | rs274 blocks/s | ours serial (s) | blocks/s | "
           "vs rs274 | ours parallel (s) [map] | blocks/s | vs rs274 | output vs rs274 |",
           "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|"]
    inner = []
    for r in data["rs274"]:
        t, b = r["times"], r["blocks"] or 0
        rs, se, pa = med(t["rs274"]), med(t["serial"]), med(t["parallel"])

        def bps(x):
            return "%.0f" % (b / x) if x and b else "-"

        def ratio(x):
            return "%.1fx" % (rs / x) if x and rs else "-"
        check = r["check"].split(None, 1)
        verdict = check[0] + (": " + check[1].split(":", 1)[-1].strip()
                              if len(check) > 1 and ":" in check[1] else "")
        if r.get("parallel_equals_serial") is False:
            verdict += "; parallel output DIFFERS from serial"
        if r["errors"]:
            verdict += "; " + ", ".join(r["errors"])
        out.append("| %s | %d | %s | %s | %s | %s | %s | %s [%s] | %s | %s | %s |" % (
            r["name"], b, fmt(rs), bps(rs), fmt(se), bps(se), ratio(se), fmt(pa),
            r["parallel_cfg"] or "-", bps(pa), ratio(pa), verdict.replace("|", "/")[:120]))
        si, pi = med(t["serial_inner"]), med(t["parallel_inner"])
        inner.append("| %s | %s | %s | %s | %s |" % (
            r["name"], fmt(si * 1e3 if si else None, 2), bps(si),
            fmt(pi * 1e3 if pi else None, 2), bps(pi)))
    return out, inner


# ---- latency ---------------------------------------------------------------------------

def pct(hist, over, q):
    n = sum(hist) + over
    if not n:
        return None
    need, acc = q * n, 0
    for us, c in enumerate(hist):
        acc += c
        if acc >= need:
            return "%d" % (us + 1)       # bin [us, us+1)
    return "> %d" % len(hist)


def lat_rows(res, where):
    rows = []
    for key, name in (("cyclictest", "cyclictest"), ("ncpar", "ncpar position loop")):
        r = res.get(key) or {}
        if r.get("error") or not r.get("hist"):
            rows.append("| %s | %s | failed: %s | | | | | |" % (
                name, where, (r.get("error") or "no data").replace("|", "/")[:100]))
            continue
        rows.append("| %s | %s | %d | %s | %s | %s | %s | %d |" % (
            name, where, r.get("cycles") or 0, fmt(r.get("min_us"), 1),
            fmt(r.get("avg_us"), 1), pct(r["hist"], r["overflow"], 0.999),
            fmt(r.get("max_us"), 1), r["overflow"]))
    return rows


# ---- the document --------------------------------------------------------------------

def driver_cmd(rows):
    """One round's table3 command line, the map replaced by OUT/maps/MAP.ini."""
    words = (rows.get("serial", {}).get("cmd") or "build/bench/table3 ...").split()
    return " ".join("OUT/maps/MAP.ini" if w.endswith("serial.ini") else w for w in words)


def keep_other_sections(path):
    """Sections of the old file not generated here, verbatim."""
    if not os.path.exists(path):
        return []
    text = open(path, encoding="utf-8").read()
    if OURS in text:
        a = text.index(OURS)
        b = text.index(OURS, a + 1) + len(OURS) if text.count(OURS) > 1 else len(text)
        text = text[:a] + text[b:]
    out, cur = [], []
    for line in text.splitlines():
        if line.startswith("## "):
            if cur:
                out.append(cur)
            cur = [line]
        elif cur:
            cur.append(line)
    if cur:
        out.append(cur)
    return ["\n".join(s).rstrip() for s in out]


def maps_md(maps_dir):
    out = ["| map | placement (CPU per thread; - = the OS decides) |", "|---|---|"]
    for base in BASES[1:]:
        p = os.path.join(maps_dir, base + ".ini")
        if not os.path.exists(p):
            continue
        sec, cpus = None, []
        for line in open(p):
            line = line.strip()
            if line.startswith("["):
                sec = line[1:-1]
            elif line.startswith("cpu") and sec:
                v = line.split("=")[1].strip()
                cpus.append("%s %s" % (sec.replace("lexer.", "LEX").replace(".0", ""),
                                       "-" if v == "-1" else v))
        out.append("| %s | %s |" % (base, ", ".join(cpus)))
    return out


def head_section(data):
    F, E = data["facts"], data["env"]
    return [OURS, "# Benchmark results", "",
         "The sections from *Machine and commands* to *3. Loop latency* are written by",
         "`make bench` (bench/run-bench: bench/bench.py measures, bench/report.py writes them",
         "and the PNGs beside this file), all from the one run dated below. The sections",
         "after them come from other scripts and carry their own dates.", "",
         "## Machine and commands (make bench)", "",
         "| | |", "|---|---|",
         "| date | %s |" % F["date"],
         "| kernel | %s `%s` (%s) |" % (F["kernel"], F["kernel_version"],
                                      "PREEMPT_RT" if F["preempt_rt"] else "not PREEMPT_RT"),
         "| CPU | %s (/proc/cpuinfo), %d CPUs online, %d usable by the run |" % (
             F["cpu_model"], F["cpus"], F["cpus_allowed"]),
         "| load average | %s at the start, %s at the end |" % (
             " ".join(F["loadavg_start"]), " ".join(F.get("loadavg_end", ["?"]))),
         "| RT throttling | sched_rt_runtime_us = %s; run as uid %d |" % (F["rt_runtime_us"],
                                                                          F["uid"]),
         "| source | git %s%s; LinuxCNC rs274 %s; rt-tests %s |" % (
             F["git"], " + uncommitted changes in src/ or include/" if F["git_dirty"] else "",
             F["rs274"] or "missing", F["rt_tests"] or "missing"),
         "| duration | %d s; settings %s |" % (F.get("duration_s", 0), ", ".join(
             "%s=%s" % kv for kv in E.items())), "",
         "Exact commands (from the top of the tree; `make bench` = `bench/run-bench build`;",
         "OUT = the run's directory, bench/out/run by default):", "",
         "```text",
         "bench/gen-maps.py OUT/maps        # thread maps for this CPU count",
         driver_cmd(data["table3_part998"]),
         driver_cmd(data["table3_big"]),
         "   (MAP = each of {serial,det2,att2,det4,att4,det8,att8}{,-fifo} in that order, all",
         "    of them once per round, %d rounds (%d for the 1M-block program): the runs of a"
         % (E.get("ROUNDS", 1), E.get("ROUNDS_BIG", 1)),
         "    configuration are spread over the suite, so that a change of load hits all",
         "    configurations alike)",
         "HOME=TMP rs274 -g -t TABLE PROG TMP/rs274.out </dev/null        # in TMP",
         "build/cnc-run parse PROG --tool-table TABLE --canon FILE --stats --mode serial",
         "build/cnc-run parse PROG --tool-table TABLE --canon FILE --stats --config OUT/maps/MAP.ini",
         "tests/tools/compare-rs274 --bin build/cnc-run --tool-table TABLE PROG",
         (data.get("latency", {}).get("background") or "") + "   # background, during:",
         ((data.get("latency", {}).get("cyclictest") or {}).get("cmd") or "cyclictest"),
         "NCPAR_PLOT_SCRIPT=NOOP.py " + ((data.get("latency", {}).get("ncpar") or {}).get(
             "cmd") or "cnc-run run") + " --trace CSV --plot PNG   # keeps CSV.latency.csv",
         "```", ""]



def table3_section(data, run_dir):
    F = data["facts"]
    bigname = os.path.basename(data["programs"]["big"])
    L = []
    n_threads = "n+3"
    L += ["## 1. Table 3 of seed 001 reproduced: Serial, DETn, ATTn", "",
          "As in the paper, *n threads* counts the active threads feeder + lexers (its Table 1:",
          "ATT4 = feeder + LEX0..2), so DETn/ATTn run n-1 lexers; our pipeline adds the",
          "analyzer, one executor and the output stage (%s threads in all, the starting"
          % n_threads,
          "thread sleeping as the paper's main thread does). The rows marked *(ours)* are not",
          "in the paper: *inline output*, feeder and one lexer, and the analyzer executing and",
          "writing each command itself (`--inline-output`), 3 threads in all; *analyzer lexes*",
          "(`-j 0 --executors 0`, the layout `cnc-run parse` uses by default on 2 CPUs), no",
          "lexer threads: the analyzer lexes the text itself and the output thread executes and",
          "writes, two busy threads (the feeder only prefaults the text). The paper timed",
          "feeder + lexers;",
          "we time the whole interpreter: from the start of `ncp_pipeline_run` (thread creation",
          "included) to the last canonical command out, as `ncp_run_stats.wall_ms` reports it",
          "(build/bench/table3 does a round's runs of one configuration in one process after",
          "an untimed warm-up run, the program mapped once; output text copied to a buffer,",
          "not written). *Without thread creation* is measured on a pre-started pool of",
          "the same map (`ncp_pipeline_pool_run`: the threads created once per process,",
          "rings reset between runs), each run right after its with-creation twin: from",
          "the start of the run to the last command out.",
          "Gain = serial mean / configuration mean at the same priority (the paper's",
          "definition); *1st/2nd half* is the same gain from each half of the runs, a",
          "measure of how much it moves within one run. Paper gains are for an Intel i3-2370M",
          "(2 cores, 4 logical CPUs) under PREEMPT_RT; it has no n = 2 rows. Rows marked *",
          "stopped early at the per-configuration time bound (T3_MAX_S). Maps (generated",
          "for %d CPUs: feeder on CPU0, lexers round-robin over the other CPUs, then"
          % F["cpus_allowed"],
          "analyzer, executor, output round-robin from CPU0; -fifo: every thread SCHED_FIFO 90;",
          "the paper's own 4-CPU ATT maps are in rt-config/paper4/):", ""]
    L += maps_md(os.path.join(run_dir, "maps")) + [""]
    for key, name in (("table3_part998", "part998.ngc"), ("table3_big", bigname)):
        rows = data[key]
        ser = rows.get("serial", {})
        L += ["### %s (%s blocks, %s commands)" % (name, ser.get("blocks", "?"),
                                                   ser.get("commands", "?")), ""]
        bad = [c for c in rows if rows[c].get("hash") and ser.get("hash")
               and rows[c]["hash"] != ser["hash"]]
        L += ["Every configuration's canonical output equals the serial reference's (hash of "
              "the text)." if not bad else "**Output differs from serial in: %s**" % ", ".join(bad),
              ""]
        warn = sorted({w for r in rows.values() for w in r.get("warnings", [])})
        if warn:
            L += ["Warnings from the runs: " + "; ".join(warn), ""]
        L += ["With thread creation (the paper's measure):", ""] + table3_md(rows, False)
        L += ["", "Without thread creation (a pre-started pool; the paper "
              "gain column repeats the paper's figures, which include thread creation):", ""]
        L += table3_md(rows, True) + [""]
        L += table3_text(rows, n_threads, name) + [""]
        L += ["Box plots: `table3-%s.png` (all configurations); per configuration "
              "`box-CONFIG.png` (both programs, with and without thread creation)." % (
                  "part998" if key == "table3_part998" else "big"), ""]
    L += ["Why ours differs from the paper (known differences of set-up, not separately "
          "measured here): this machine has %d CPUs where the paper had 4 logical CPUs, so "
          "each of the paper's configurations runs more threads (n+3, at least 5) than there "
          "are CPUs and ATT "
          "stacks several threads on one CPU; the kernel is %s; our pipeline has three "
          "stages more than the paper's feeder + lexers, each a hand-off between threads, and we time up to the "
          "last command out, not the lexers alone; and the program differs (ours: "
          "part998.ngc, written for this, and a generated 1M-block program; the paper's "
          "998-block program is not published). On the 1M-block program start-up is a small "
          "share of each run (see the share of ring allocation and thread creation above), "
          "so its gains are the better measure of the pipeline's throughput here." % (
              F["cpus_allowed"], "PREEMPT_RT" if F["preempt_rt"]
              else "%s, not PREEMPT_RT as in the paper" % F["kernel"]), ""]
    return L


def rs274_section(data):
    L = []
    md, inner = rs274_md(data)
    fl = data.get("startup_floor", {})
    L += ["## 2. Against LinuxCNC: rs274 -g vs cnc-run parse", "",
          "Each program: rs274, our serial run and our best parallel map (the lowest mean "
          "on part998 for part998, on the 1M-block program for the others, from section 1) "
          "run one after the other, repeated RS_REPS times (RS_REPS_BIG for programs over "
          "5 MB), interleaved; the table gives medians of the whole process's wall time, "
          "both writing canonical text to a file. Blocks = lines our feeder read. The three "
          "ncfiles are the largest in %s that rs274 accepts and rs274-skip.txt does not "
          "exclude. *Output vs rs274* is tests/tools/compare-rs274 (same calls, numbers "
          "within 1e-4); the parallel output is also compared byte for byte with the "
          "serial one." % "/usr/share/linuxcnc/ncfiles", ""] + md + [""]
    if fl:
        L += ["Start-up floor (a 2-block program, best of 5): rs274 %.1f ms, cnc-run %.1f ms. "
              "On the small programs the process times, and so the ratios, are mostly this "
              "start-up; the 1M-block program shows the interpreters' throughput." % (
                  fl["rs274"] * 1e3, fl["ours"] * 1e3), ""]
    tables = {}
    for r in data["rs274"]:
        tables.setdefault(r["table"], []).append(r["name"])
    L += ["Tool tables (the same for both interpreters): " + "; ".join(
        "%s for %s" % (t, ", ".join(n)) for t, n in tables.items()) + ".", ""]
    L += rs274_text(data) + [""]
    L += ["Our interpreter alone (the --stats wall time, no process start-up or mmap):", "",
          "| program | serial (ms) | blocks/s | parallel (ms) | blocks/s |",
          "|---|--:|--:|--:|--:|"] + inner + [""]
    return L


def latency_section(data, outdir):
    bigname = os.path.basename(data["programs"]["big"])
    L = []
    lat, guest = data.get("latency", {}), data.get("latency_guest", {})
    L += ["## 3. Loop latency: cyclictest vs the ncpar position loop", "",
          "Both at 1 ms, SCHED_FIFO 90, in the same run one after the other (%s s each), "
          "while a loop of `cnc-run parse` interprets %s in the background the whole time. "
          "cyclictest -S runs one thread per CPU (both counted); our loop is one thread, "
          "`cnc-run run %s --for %s` on rt-config/sim-3axis.ini (planner, interpolator and "
          "simulated servo running too). p99.9 is the upper edge of the 1 us bin where 99.9 %% "
          "of the cycles are reached; '> 1000' when it lies beyond the histogram." % (
              fmt(lat.get("seconds"), 0), bigname, bigname, fmt(lat.get("seconds"), 0)), "",
          "| loop | where | cycles | min (us) | avg (us) | p99.9 (us) | max (us) | > 1 ms |",
          "|---|---|--:|--:|--:|--:|--:|--:|"]
    L += lat_rows(lat, lat.get("label", "host"))
    if guest.get("skipped"):
        L += ["", "PREEMPT_RT guest: not measured (%s)." % guest["skipped"]]
    elif guest:
        L += lat_rows(guest, guest.get("label", "guest"))
        L += ["", "Guest rows: `%s` (part998.ngc as the program and as the background load: "
              "under emulation the 1M-block program's pre-pass alone takes too long)." %
              guest.get("cmd", "tools/rtvm/run -- bench/latency.py ...")]
    sets = [("this host", lat)] + ([("RT guest, %s" % (
        "TCG emulation: NOT latency figures" if guest.get("where") == "tcg"
        else guest.get("where")), guest)]
                                   if guest and not guest.get("skipped") else [])
    if plots.latency_png(os.path.join(outdir, "latency.png"), sets):
        L += ["", "Histograms side by side: `latency.png` (log scale; red: beyond 1 ms)."]
    return L + ["", latency_text(lat, guest)]


def main():
    data = json.load(open(sys.argv[1]))
    results = sys.argv[2]
    outdir = os.path.dirname(os.path.abspath(results))
    run_dir = os.path.dirname(os.path.abspath(sys.argv[1]))
    others = keep_other_sections(results)
    plots_table3(data, outdir)
    L = (head_section(data) + table3_section(data, run_dir) + rs274_section(data)
         + latency_section(data, outdir) + ["", OURS, ""])
    with open(results, "w", encoding="utf-8") as f:
        f.write("\n".join(L) + "\n" + "\n\n".join(others) + ("\n" if others else ""))


def rs274_text(data):
    big = [r for r in data["rs274"] if r["prog"] == data["programs"]["big"]]
    if not big or not med(big[0]["times"]["rs274"]) or not med(big[0]["times"]["serial"]):
        return []
    t = big[0]["times"]
    rs, se, pa = med(t["rs274"]), med(t["serial"]), med(t["parallel"])
    out = "On the 1M-block program our serial run is %.1fx as fast as rs274" % (rs / se)
    if pa:
        out += " and the best parallel map (%s) %.1fx, %s than our serial run" % (
            big[0]["parallel_cfg"], rs / pa, "faster" if pa < se else "slower")
    fails = [r["name"] for r in data["rs274"] if not r["check"].startswith("PASS")]
    return [out + ". " + ("Every program's output matches rs274's." if not fails else
                          "Output does NOT match rs274 for: %s (see the last column)."
                          % ", ".join(fails)) +
            " The paper has no comparison with another interpreter."]


def latency_text(lat, guest):
    c, n = lat.get("cyclictest") or {}, lat.get("ncpar") or {}
    parts = []
    if c.get("max_us") is not None and n.get("max_us") is not None:
        parts.append("Here the worst wake-up was %.0f us for cyclictest and %.0f us for our "
                     "loop, averages %.1f and %.1f us." % (c["max_us"], n["max_us"],
                                                          c.get("avg_us") or math.nan,
                                                          n.get("avg_us") or math.nan))
    where = {"stock": "a stock (non-PREEMPT_RT) kernel", "rt": "a PREEMPT_RT host",
             "kvm": "a PREEMPT_RT guest under KVM",
             "tcg": "an emulated guest"}.get(lat.get("where"), "this host")
    parts.append("These come from %s: they show how the loop behaves beside the "
                 "yardstick on the same machine and load%s (the paper ran PREEMPT_RT but "
                 "published no latency figures). cyclictest does nothing but wake up; our "
                 "loop also runs the servo cycle, and the planner and interpreter threads of "
                 "`cnc-run run` share the CPUs with it." % (
                     where, ", not what it achieves on a real-time kernel"
                     if lat.get("where") == "stock" else ""))
    if guest and not guest.get("skipped") and guest.get("where") == "tcg":
        parts.append("The guest rows ran under qemu TCG software emulation: they are NOT "
                     "latency figures and say nothing about the code.")
    return " ".join(parts)


if __name__ == "__main__":
    main()
