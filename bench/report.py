#!/usr/bin/python3
"""report.py DATA.json RESULTS.md: writes the `make bench` sections of RESULTS.md
and the PNGs beside it from one run's measurements (bench/bench.py).

Only the part between the two OURS marker lines is replaced; everything before
and after it (the introduction, the sections of other benchmarks, the findings)
stays as it is, in place. A file without the markers gets the part appended."""
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


def short_label(base):
    if base.startswith("paper4-"):
        return short_label(base[len("paper4-"):]) + " (paper's 4-CPU map)"
    if base.endswith("-inline"):
        return base + " (ours: inline output)"
    if base.endswith("-j0"):
        return base + " (ours: analyzer lexes)"
    return base


def table3_compact_md(rows):
    """One row per map: mean and gain at both priorities, with thread creation and
    on the pre-started pool; the paper's gains beside them."""
    out = ["| map | Non RT: mean (ms) | gain | gain, pool | Prio 90: mean (ms) | gain | "
           "gain, pool | paper gain, Non RT / Prio 90 |",
           "|---|--:|--:|--:|--:|--:|--:|--:|"]
    for base in bases(rows):
        cells = [short_label(base)]
        for fifo in ("", "-fifo"):
            cfg = base + fifo
            row = rows.get(cfg, {})
            s = stats(series(row, False))
            if not s:
                cells += ["failed: %s" % row.get("error", "no runs").replace("|", "/")[:60],
                          "", ""]
                continue
            mean = fmt(s["mean"]) + ("*" if row.get("stopped") else "")
            if base == "serial":
                cells += [mean, "-", "-"]
            else:
                cells += [mean, fmt(gains(rows, cfg, False)[0], 2),
                          fmt(gains(rows, cfg, True)[0], 2)]
        key = base.replace("paper4-", "")
        pg = (PAPER_GAIN.get(key), PAPER_GAIN.get(key + "-fifo"))
        cells.append("%.2f / %.2f" % pg if pg[0] else
                     "(serial %.3f / %.3f ms)" % (PAPER_SERIAL_MS[""], PAPER_SERIAL_MS["-fifo"])
                     if base == "serial" else "-")
        out.append("| " + " | ".join(cells) + " |")
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


def splice(path, part):
    """The file's text with the part between the OURS markers replaced by part (a
    list of lines starting and ending with OURS); appended when there are no markers,
    under a title when there is no file."""
    block = "\n".join(part) + "\n"
    if not os.path.exists(path):
        return "# Benchmark results\n\n" + block
    text = open(path, encoding="utf-8").read()
    if text.count(OURS) >= 2:
        a = text.index(OURS)
        b = text.index(OURS, a + len(OURS)) + len(OURS)
        rest = text[b:]
        return text[:a] + block.rstrip("\n") + ("" if rest.startswith("\n") else "\n") + rest
    return text.rstrip("\n") + "\n\n" + block


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
    return [OURS, "<!-- From here to the next marker line: written by every `make bench` "
            "(bench/report.py); change that script, not this text. -->", "",
         "## `make bench`: machine, date and commands", "",
         "The next three sections come from one `make bench` run, described here.", "",
         "| | |", "|---|---|",
         "| date | %s |" % F["date"],
         "| machine | %s |" % (F.get("lscpu") or "%s (/proc/cpuinfo), %d CPUs" % (
             F["cpu_model"], F["cpus"])),
         "| CPUs used | %d of %d online |" % (F["cpus_allowed"], F["cpus"]),
         "| kernel | %s `%s` (%s) |" % (F["kernel"], F["kernel_version"],
                                      "PREEMPT_RT" if F["preempt_rt"] else "not PREEMPT_RT"),
         "| load average | %s at the start, %s at the end |" % (
             " ".join(F["loadavg_start"]), " ".join(F.get("loadavg_end", ["?"]))),
         "| RT throttling | sched_rt_runtime_us = %s; run as uid %d |" % (F["rt_runtime_us"],
                                                                          F["uid"]),
         "| source | git %s%s; LinuxCNC rs274 %s; rt-tests %s |" % (
             F["git"], " + uncommitted changes in src/ or include/" if F["git_dirty"] else "",
             F["rs274"] or "missing", F["rt_tests"] or "missing"),
         "| duration | %d s |" % F.get("duration_s", 0),
         "| settings | %s |" % ", ".join("%s=%s" % kv for kv in E.items()), "",
         "The run, from the top of the tree (`make bench` = build, then `bench/run-bench "
         "build`; the settings above are its environment variables, e.g. "
         "`RUNS=20 RUNS_BIG=3 LAT_SECONDS=5 make bench` for a quick run):", "",
         "```sh",
         " ".join("%s=%s" % kv for kv in E.items()) + " make bench",
         "```", "",
         "What it runs (OUT = the run's directory, bench/out/run by default):", "",
         "```text",
         "bench/gen-maps.py OUT/maps        # thread maps for this CPU count",
         driver_cmd(data["table3_part998"]),
         driver_cmd(data["table3_big"]),
         "   (MAP = each of the maps below, normal and -fifo, one after the other, all of",
         "    them once per round, %d rounds (%d for the 1M-block program), so that a change"
         % (E.get("ROUNDS", 1), E.get("ROUNDS_BIG", 1)),
         "    of load on the machine hits all configurations alike)",
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
    L = ["## Table 3 of the interpreter-pipeline paper: serial, DETn, ATTn (`make bench`)", "",
         "**Measures** the paper's Table 3 on our interpreter: the time from the start of a",
         "run (thread creation included) to the last canonical command out, for the serial",
         "reference and each thread map, on part998.ngc (996 blocks) and on %s;" % bigname,
         "*gain* = serial mean / the map's mean at the same priority, as the paper defines",
         "it. *Pool*: the same map on threads created once (`ncp_pipeline_pool_run`), so",
         "without thread creation. One process per round of a map (build/bench/table3), the",
         "program mapped once, the text copied to a buffer, not written.", "",
         "**Maps.** As in the paper, DETn/ATTn have n threads of feeder + lexers (n-1",
         "lexers); ours adds the analyzer, one executor and the output stage (n+3 threads).",
         "DET lets the OS place the threads, ATT pins them as below; *Prio 90* runs every",
         "thread SCHED_FIFO 90. Not in the paper: *inline output* (feeder, one lexer, the",
         "analyzer executing and writing: 3 threads) and *analyzer lexes* (`-j 0",
         "--executors 0`, the default of `cnc-run parse` on 2 CPUs: the analyzer lexes, the",
         "output thread executes, writes and lexes ahead; two busy threads). Paper gains:",
         "Intel i3-2370M (2 cores, 4 logical CPUs), PREEMPT_RT, no n = 2 rows. * = stopped",
         "at the per-map time bound (T3_MAX_S). Placement on this machine (%d CPUs):"
         % F["cpus_allowed"], ""]
    L += maps_md(os.path.join(run_dir, "maps")) + [""]
    for key, name in (("table3_part998", "part998.ngc"), ("table3_big", bigname)):
        rows = data[key]
        ser = rows.get("serial", {})
        L += ["### %s (%s blocks, %s commands)" % (name, ser.get("blocks", "?"),
                                                   ser.get("commands", "?")), ""]
        bad = [c for c in rows if rows[c].get("hash") and ser.get("hash")
               and rows[c]["hash"] != ser["hash"]]
        warn = sorted({w for r in rows.values() for w in r.get("warnings", [])})
        L += table3_compact_md(rows) + [""]
        L += [("Every map's canonical output equals the serial reference's (hash of the "
               "text). " if not bad else "**Output differs from serial in: %s.** "
               % ", ".join(bad)) + " ".join(table3_text(rows, "n+3", name))]
        if warn:
            L += ["", "Warnings from the runs: " + "; ".join(warn)]
        L += ["", "Spread of the runs: `table3-%s.png`, and `box-MAP.png` per map." % (
            "part998" if key == "table3_part998" else "big"), ""]
    L += ["Why the paper's gains are not reached here: this machine has %d CPUs where the "
          "paper had 4 logical CPUs, so its maps run more threads (n+3) than there are CPUs; "
          "the kernel is %s; our pipeline has three stages more than the paper's feeder + "
          "lexers, each a hand-off between cores (see *How we got here*), and we time to the "
          "last command out, not the lexers alone. On the 1M-block program start-up is a "
          "small share of a run, so its gains measure the pipeline's throughput." % (
              F["cpus_allowed"], "PREEMPT_RT" if F["preempt_rt"]
              else "%s, not PREEMPT_RT" % F["kernel"]), ""]
    return L


def rs274_section(data):
    L = []
    md, inner = rs274_md(data)
    fl = data.get("startup_floor", {})
    L += ["## Against LinuxCNC: rs274 -g vs cnc-run parse (`make bench`)", "",
          "**Measures** whole-process wall time of LinuxCNC's interpreter and ours on the "
          "same programs, and checks that both produce the same canonical calls. Each program: rs274, our serial run and our best parallel map (the lowest mean "
          "on part998 for part998, on the 1M-block program for the others, from Table 3) "
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
    L += ["## Loop latency: cyclictest vs the ncpar position loop (`make bench`)", "",
          "**Measures** how late the 1 ms position loop wakes up, beside cyclictest (the "
          "usual yardstick) on the same machine and load. Both at 1 ms, SCHED_FIFO 90, in the same run one after the other (%s s each), "
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
        L += ["", "PREEMPT_RT guest: not measured (%s)." % " ".join(guest["skipped"].split())]
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
    plots_table3(data, outdir)
    part = (head_section(data) + table3_section(data, run_dir) + rs274_section(data)
            + latency_section(data, outdir) + ["", OURS])
    text = splice(results, part)
    with open(results, "w", encoding="utf-8") as f:
        f.write(text)


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
