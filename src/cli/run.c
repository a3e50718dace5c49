/* cnc-run run: the full NCK (interpreter -> planner -> interpolator -> position
 * loop) on the simulated machine. Option parsing, loading and reporting; the
 * runtime itself is ncp_nck_run (src/rt/). */
#include "run.h"
#include "backend_opts.h"
#include "channels.h"
#include "nck_run.h"
#include "inject_opts.h"
#include "key_opts.h"
#include "machine.h"
#include "outfile.h"
#include "rs274_ini.h"
#include "signals.h"

#include "ncpar/backend.h"
#include "ncpar/config.h"
#include "ncpar/dist.h"
#include "ncpar/feeder.h"
#include "ncpar/msg.h"
#include "ncpar/pipeline.h"
#include "ncpar/nck.h"
#include "ncpar/num.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

struct run_opts {
    const char *prog, *config, *trace, *plot, *tool_table, *sub_path;
    double for_s;               /* 0 = whole program */
    double feed_override;       /* 1.0 = 100 % */
    int virtual_clock;
    enum ncp_thread_mode mode;
    const char *backend;        /* --backend as given, NULL = sim */
    int dp;                     /* --dp, 0 = the INI's [LCM] DP */
    const char *lcm_url;        /* --lcm-url, NULL = the INI's [LCM] URL */
    const char *key_file;       /* --key-file, NULL = the INI's [LCM] KEY_FILE */
    uint32_t max_loops;         /* --max-loops, 0 = the interpreter's default */
    const char *inject, *seed;  /* --inject SPECS, --seed N (NULL: the INI's) */
    int home;                   /* --home: home the machine before the program */
    int trace_rings;            /* --trace-rings: ring and task columns in the trace */
    const char *channel[NCP_CLI_CHANNELS_MAX]; /* --channel N:PROG[:INI], as given */
    int n_channels;
};

static void usage(FILE *f)
{
    fputs("usage: cnc-run run PROG [--config INI] [--trace CSV] [--plot PNG] [--for SECONDS]\n"
          "                        [--feed-override PCT] [--clock real|virtual]\n"
          "                        [--mode serial|det|att] [--tool-table FILE]\n"
          "                        [--subroutine-path DIR[:DIR...]] [--max-loops N]\n"
          "                        [--backend sim|socketcan[:IFACE]|lcm] [--dp N] [--lcm-url URL]\n"
          "                        [--inject SPEC[,SPEC...]] [--seed N] [--home]\n"
          "       cnc-run run --channel N:PROG[:INI] [--channel M:PROG2[:INI2] ...] [options]\n"
          "Runs PROG on the simulated machine (or CiA 402 drives over CAN): interpreter ->\n"
          "look-ahead planner -> interpolator -> position loop (SCHED_FIFO when permitted).\n"
          "  --config INI        machine INI (default: built-in 3-axis mill); its [RS274NGC]\n"
          "                      (REMAP, SUBROUTINE_PATH, USER_M_PATH: M100-M199 run their\n"
          "                      executables, the machine at rest) configures the\n"
          "                      interpreter, as in LinuxCNC (docs/remap.md)\n"
          "  --ini INI           the same as --config (parse's name for it)\n"
          "  --trace CSV         per-cycle trace: t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion\n"
          "                      (motion: 0 rapid, 1 feed, 2 arc); an existing CSV (the\n"
          "                      last run's) is kept as CSV.1\n"
          "  --trace-rings       add the task chain to the trace: seg_fill,seg_cap,sp_fill,\n"
          "                      sp_cap (segment and setpoint rings), job_cycle_us,\n"
          "                      plan_resp_us, plan_cycle_us, loop_cycle_us (as [SCHED]\n"
          "                      TRACE_RINGS = 1)\n"
          "  --plot PNG          picture of the run (tools/plot-trace.py, python3-matplotlib):\n"
          "                      XY toolpath, velocity/acceleration, latency histogram\n"
          "  --for SECONDS       stop after this much machine time\n"
          "  --home              home the machine first, as `cnc-ctl home all` does (the\n"
          "                      INI's HOME_* keys; the trace's last column shows each\n"
          "                      axis's phase); without it the machine starts homed\n"
          "  --feed-override PCT 1..200 (default 100)\n"
          "  --clock virtual     simulated clock, as fast as the CPU allows\n"
          "  --tool-table FILE   LinuxCNC tool table (default: rs274's built-in T1-T3)\n"
          "  --subroutine-path DIRS  where o<name> call finds name.ngc after the current\n"
          "                      folder (colon-separated, as rs274's SUBROUTINE_PATH)\n"
          "  --max-loops N       a loop (while/do/repeat, M98 L, G76 passes) may repeat N\n"
          "                      times before it counts as runaway (default 10000000)\n"
          "  --backend sim       the simulated machine (default: the INI's [EMCMOT]\n"
          "                      BACKEND, else sim)\n"
          "  --backend socketcan[:IFACE]  CiA 402 drives in CSP mode over SocketCAN on\n"
          "                      IFACE (default: the INI's [CAN] INTERFACE); each axis\n"
          "                      needs [AXIS_n] NODE_ID and COUNTS_PER_MM; real clock only.\n"
          "                      A drive fault (EMCY, heartbeat loss, drive leaving\n"
          "                      Operation enabled, SDO failure) stops all axes: exit 3.\n"
          "                      The trace's actual positions are then the drives' TPDOs,\n"
          "                      one servo period old\n"
          "  --backend lcm       the distributed NCK: one `cnc-axis` per axis of the INI\n"
          "                      over LCM (docs/distributed.md); real clock only.\n"
          "                      An axis lost (no status for [LCM] MAX_LOST_PERIODS, no\n"
          "                      heartbeat) stops the others: exit 3\n"
          "  --dp N              distribution point 1..5 (default: the INI's [LCM] DP, 5);\n"
          "                      implemented: 5 (fine setpoints every servo period);\n"
          "                      ADCBI 4, 3, 2 (ACCDECbuf, LAbuf, INTbuf records) and 1\n"
          "                      (each LLC runs the program itself, from its path)\n"
          "  --lcm-url URL       udpm://GROUP:PORT?ttl=N (default: [LCM] URL, $LCM_DEFAULT_URL)\n"
          "  --key-file F        the key that seals every message to and from the axes\n"
          "                      (default: [LCM] KEY_FILE, else ~/.config/ncpar/lcm.key;\n"
          "                      made when missing, as cnc-run serve does)\n"
          "  --inject SPECS      timing faults in the position loop (over the INI's [INJECT]\n"
          "                      SPEC): miss=RATIO, miss@CYCLE, latency=US, latency=MIN-MAX,\n"
          "                      io-latency=US, jitter=US[:normal], lose-setpoint=RATIO,\n"
          "                      lose-feedback=RATIO, delay-feedback=US; the trace gets an\n"
          "                      inject column. [RT] MISS_POLICY says what a servo runs on\n"
          "                      when its setpoint is late or lost\n"
          "  --seed N            the faults' random seed (default: the INI's SEED, or 1)\n"
          "  --channel N:PROG[:INI]  NC channel N (0..15) runs PROG on its own machine INI\n"
          "                      (default: the built-in mill), planner, position loop and\n"
          "                      simulated machine, beside the other channels in this\n"
          "                      process; each channel's summary lines start 'chN: '.\n"
          "                      --trace names a file per channel: {channel} in it is\n"
          "                      replaced by N, else .chN goes before the extension.\n"
          "                      A fault stops its own channel only; the exit status is\n"
          "                      the worst channel's\n"
          "exit status: 0 ok, 1 usage, 2 program error, 3 runtime fault / soft limit\n",
          f);
}

static int parse_opts(int argc, char **argv, struct run_opts *o)
{
    static const struct option longopts[] = {
        { "config", required_argument, 0, 'c' },
        { "ini", required_argument, 0, 'N' },
        { "trace", required_argument, 0, 't' },
        { "plot", required_argument, 0, 'p' },
        { "for", required_argument, 0, 'f' },
        { "feed-override", required_argument, 0, 'o' },
        { "clock", required_argument, 0, 'k' },
        { "mode", required_argument, 0, 'm' },
        { "tool-table", required_argument, 0, 'T' },
        { "subroutine-path", required_argument, 0, 'S' },
        { "backend", required_argument, 0, 'b' },
        { "dp", required_argument, 0, 'D' },
        { "lcm-url", required_argument, 0, 'U' },
        { "key-file", required_argument, 0, 'K' },
        { "max-loops", required_argument, 0, 'L' },
        { "inject", required_argument, 0, 'I' },
        { "seed", required_argument, 0, 'R' },
        { "home", no_argument, 0, 'H' },
        { "trace-rings", no_argument, 0, 'G' },
        { "channel", required_argument, 0, 'C' },
        { "help", no_argument, 0, 'h' },
        { 0, 0, 0, 0 },
    };
    double pct;
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "c:t:p:f:o:k:m:hT:b:S:L:I:R:HD:U:", longopts, NULL)) != -1) {
        switch (c) {
        case 'c': case 'N':
            if (ncp_cli_set_config("cnc-run run", &o->config, optarg))
                return -1;
            break;
        case 't': o->trace = optarg; break;
        case 'p': o->plot = optarg; break;
        case 'T': o->tool_table = optarg; break;
        case 'S': o->sub_path = optarg; break;
        case 'b': o->backend = optarg; break;
        case 'D':
            if (ncp_num_double(optarg, 1, 5, &pct) || pct != floor(pct) || strchr(optarg, '.') ||
                strpbrk(optarg, "eE"))
                return fprintf(stderr, "cnc-run run: --dp is a distribution point 1..5, not "
                                       "'%s'\n", optarg), -1;
            o->dp = (int)pct;
            break;
        case 'U': o->lcm_url = optarg; break;
        case 'K': o->key_file = optarg; break;
        case 'I': o->inject = optarg; break;
        case 'R': o->seed = optarg; break;
        case 'H': o->home = 1; break;
        case 'G': o->trace_rings = 1; break;
        case 'C':
            if (o->n_channels == NCP_CLI_CHANNELS_MAX)
                return fprintf(stderr, "cnc-run run: at most %d channels\n",
                               NCP_CLI_CHANNELS_MAX), -1;
            o->channel[o->n_channels++] = optarg;
            break;
        case 'L':
            if (ncp_num_double(optarg, 1, 2000000000, &pct) || pct != floor(pct))
                return fprintf(stderr, "cnc-run run: --max-loops wants a positive count\n"), -1;
            o->max_loops = (uint32_t)pct;
            break;
        case 'f':
            if (ncp_num_double(optarg, 1e-6, 1e9, &o->for_s))
                return fprintf(stderr, "cnc-run run: --for wants a positive number of seconds\n"), -1;
            break;
        case 'o':
            /* 0 % would never finish: a static override starts at 1 % */
            if (ncp_num_double(optarg, 1, 200, &pct))
                return fprintf(stderr, "cnc-run run: --feed-override wants 1..200 (%%)\n"), -1;
            o->feed_override = pct / 100.0;
            break;
        case 'k':
            if (!strcmp(optarg, "real") || !strcmp(optarg, "virtual"))
                o->virtual_clock = !strcmp(optarg, "virtual");
            else
                return fprintf(stderr, "cnc-run run: --clock is real or virtual\n"), -1;
            break;
        case 'm':
            if (ncp_thread_mode_parse(optarg, &o->mode))
                return fprintf(stderr, "cnc-run run: --mode is serial, det or att\n"), -1;
            break;
        case 'h': usage(stdout); exit(RUN_OK);
        default: return -1;
        }
    }
    if (o->n_channels && optind != argc)
        return fprintf(stderr, "cnc-run run: with --channel each program is named in its "
                               "--channel, not '%s'\n", argv[optind]), -1;
    if (o->n_channels)
        return 0;
    if (optind != argc - 1)
        return fprintf(stderr, "cnc-run run: expected exactly one program file\n"), -1;
    o->prog = argv[optind];
    return 0;
}

/* The lines of a program held in memory are counted; a mapped one (longer
 * than NCP_SOURCE_COPY_MAX) is not read through before motion, which would
 * take a pass over gigabytes before the first move: its count is estimated
 * from its first stretch, the rest taken to have lines as long on average. */
#define COUNT_SAMPLE ((uint64_t)1 << 20)

static uint32_t count_lines(const struct ncp_source *src, int *approx)
{
    uint64_t end = src->len;
    *approx = src->mapped && end > COUNT_SAMPLE;
    if (*approx)
        end = ncp_source_chunk_end(src, 0, COUNT_SAMPLE);
    uint64_t n = ncp_source_count_newlines(src, 0, end);
    if (*approx) {
        double est = (double)src->len * (double)n / (double)(end ? end : 1);
        n = est < UINT32_MAX - 1.0 ? (uint64_t)est : UINT32_MAX - 1;
    }
    return (uint32_t)(n + 1);
}

/* DP 1: the LLCs read the program (and its tool table) themselves, on this
 * host, by absolute path; they plan at 100 % feed. */
static int apply_dp1(const struct run_opts *o, struct ncp_machine_cfg *cfg)
{
    char abs[PATH_MAX];
    if (o->feed_override != 1.0)
        return fprintf(stderr, "cnc-run run: --backend lcm --dp 1: the LLCs plan the program "
                               "at 100 %% feed: no --feed-override\n"), -1;
    if (!strcmp(o->prog, "-"))
        return fprintf(stderr, "cnc-run run: --backend lcm --dp 1: the LLCs read the program "
                               "from its file: not from standard input\n"), -1;
    const char *in[2] = { o->prog, o->tool_table };
    char *out[2] = { cfg->lcm.program, cfg->lcm.tool_table };
    for (int i = 0; i < 2; i++) {
        out[i][0] = 0;
        if (!in[i])
            continue;
        if (!realpath(in[i], abs) || strlen(abs) >= sizeof cfg->lcm.program)
            return fprintf(stderr, "cnc-run run: --backend lcm --dp 1: %s: %s\n", in[i],
                           strerror(errno ? errno : ENAMETOOLONG)), -1;
        snprintf(out[i], sizeof cfg->lcm.program, "%s", abs);
    }
    if (o->sub_path && strlen(o->sub_path) >= sizeof cfg->lcm.sub_path)
        return fprintf(stderr, "cnc-run run: --backend lcm --dp 1: --sub-path too long\n"), -1;
    snprintf(cfg->lcm.sub_path, sizeof cfg->lcm.sub_path, "%s", o->sub_path ? o->sub_path : "");
    return 0;
}

/* DP 1's LLCs interpret the program with the command line's folders and
 * tool table only: an INI whose [RS274NGC] changes what the program does
 * there (REMAP, user M codes, its keys) would have the HLC and the LLCs
 * run different programs, so it is refused before anything moves. */
static int dp1_interpreter_refused(const struct ncp_machine_cfg *cfg,
                                   const struct ncp_analyzer_cfg *acfg)
{
    if (cfg->backend != NCP_BACKEND_LCM || cfg->lcm.dp != 1)
        return 0;
    const char *what = acfg->n_remaps                             ? "REMAP lines"
                       : acfg->user_m_dirs && *acfg->user_m_dirs ? "user M codes (USER_M_PATH, "
                                                                   "PROGRAM_PREFIX)"
                       : acfg->oword_nargs || acfg->orient_offset != 0.0 || acfg->no_fanuc_subs
                           ? "OWORD_NARGS, ORIENT_OFFSET or DISABLE_FANUC_STYLE_SUB"
                       : acfg->subroutine_path &&
                               strcmp(acfg->subroutine_path, cfg->lcm.sub_path) != 0
                           ? "SUBROUTINE_PATH"
                           : NULL;
    if (!what)
        return 0;
    fprintf(stderr, "cnc-run run: --backend lcm --dp 1: each LLC interprets the program "
                    "without the INI's [RS274NGC] %s; use DP 2-5 with this INI\n", what);
    return -1;
}

/* --backend, over the INI's [EMCMOT] BACKEND (backend_opts.c, as serve's);
 * DP 1's program is this command's own. */
static int apply_backend(const struct run_opts *o, struct ncp_machine_cfg *cfg)
{
    const struct ncp_cli_backend_opts bo = { "cnc-run run", o->config, o->backend, o->dp,
                                             o->lcm_url, o->key_file, o->virtual_clock };
    int lcm = o->backend ? !strcmp(o->backend, "lcm") : cfg->backend == NCP_BACKEND_LCM;
    if (!lcm && (o->dp || o->lcm_url || o->key_file))
        return fprintf(stderr, "cnc-run run: --dp, --lcm-url and --key-file go with --backend "
                               "lcm\n"), -1;
    if (ncp_cli_apply_backend(&bo, cfg))
        return -1;
    return cfg->backend == NCP_BACKEND_LCM && cfg->lcm.dp == 1 ? apply_dp1(o, cfg) : 0;
}

static int load_config(const struct run_opts *o, struct ncp_machine_cfg *cfg)
{
    return ncp_cli_load_machine(o->config, cfg) || apply_backend(o, cfg) ||
                   ncp_cli_apply_inject("cnc-run run", o->inject, o->seed, cfg)
               ? -1
               : 0;
}


/* ---- --plot: the trace and a latency sidecar handed to tools/plot-trace.py ---- */

/* The script sits in tools/ of the source tree the binary was built in
 * (build/cnc-run -> ../tools); NCPAR_PLOT_SCRIPT overrides that. */
static int find_plot_script(char *buf, size_t n)
{
    const char *env = getenv("NCPAR_PLOT_SCRIPT");
    if (env && *env)
        return snprintf(buf, n, "%s", env) < (int)n ? 0 : -1;
    char exe[4096];
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (k <= 0)
        return -1;
    exe[k] = 0;
    char *slash = strrchr(exe, '/');
    if (!slash)
        return -1;
    *slash = 0;
    static const char *const rel[] = { "/../tools/plot-trace.py", "/../../tools/plot-trace.py",
                                       "/tools/plot-trace.py" };
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
        if (snprintf(buf, n, "%s%s", exe, rel[i]) < (int)n && access(buf, R_OK) == 0)
            return 0;
    }
    return -1;
}

/* Sidecar format (documented in tools/plot-trace.py): "latency_us,cycles",
 * one row per non-empty 1 us bin, then ">=1000,N" when anything overflowed. */
static int write_latency(const char *path, const struct ncp_rt_stats *st)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fputs("latency_us,cycles\n", f);
    for (int i = 0; i < NCP_RT_HIST_BINS; i++)
        if (st->hist[i])
            fprintf(f, "%d,%llu\n", i, (unsigned long long)st->hist[i]);
    if (st->overflow)
        fprintf(f, ">=%d,%llu\n", NCP_RT_HIST_BINS, (unsigned long long)st->overflow);
    return fclose(f) ? -1 : 0;
}

/* What --plot needs, known before anything moves: the place for the picture
 * (plot->out, opened), the script, python3 with matplotlib, and a private
 * folder for the files handed to it (the trace when --trace is not given,
 * the latency sidecar, the picture), all removed afterwards. */
struct plot_job {
    struct ncp_outfile out;
    char script[4096];
    char dir[512];
    char trace[544], side[544], png[544];
};

static int plot_prepare(struct plot_job *pj, const char *path, const struct ncp_file_id *ids,
                        int n_ids)
{
    memset(pj, 0, sizeof *pj);
    pj->out.fd = -1;
    if (ncp_outfile_open(&pj->out, path, ids, n_ids, NCP_OUT_SYNC) != 0)
        return -1;
    if (find_plot_script(pj->script, sizeof pj->script)) {
        fprintf(stderr, "cnc-run run: --plot: cannot find tools/plot-trace.py (set NCPAR_PLOT_SCRIPT)\n");
        ncp_outfile_discard(&pj->out);
        return -1;
    }
    /* the import is what fails on a machine without matplotlib: find out now */
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        execl("/usr/bin/python3", "python3", "-c", "import matplotlib", (char *)NULL);
        _exit(127);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "cnc-run run: --plot needs /usr/bin/python3 with matplotlib "
                        "(python3-matplotlib)\n");
        ncp_outfile_discard(&pj->out);
        return -1;
    }
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !*tmp || strlen(tmp) > 400)
        tmp = "/tmp";
    snprintf(pj->dir, sizeof pj->dir, "%s/cnc-run-plot-XXXXXX", tmp);
    if (!mkdtemp(pj->dir)) {
        fprintf(stderr, "cnc-run run: --plot: cannot make a folder in %s: %s\n", tmp,
                strerror(errno));
        ncp_outfile_discard(&pj->out);
        pj->dir[0] = 0;
        return -1;
    }
    snprintf(pj->trace, sizeof pj->trace, "%s/trace.csv", pj->dir);
    snprintf(pj->side, sizeof pj->side, "%s/latency.csv", pj->dir);
    /* ".png": the script's matplotlib then writes exactly this name */
    snprintf(pj->png, sizeof pj->png, "%s/plot.png", pj->dir);
    return 0;
}

static void plot_clean(struct plot_job *pj)
{
    if (pj->out.fd >= 0 || pj->out.tmp)
        ncp_outfile_discard(&pj->out);
    if (!pj->dir[0])
        return;
    unlink(pj->trace);
    unlink(pj->side);
    unlink(pj->png);
    rmdir(pj->dir);
    pj->dir[0] = 0;
}

/* 0, or the errno of the failed read or write. */
static int copy_file(const char *from, int to)
{
    int in = open(from, O_RDONLY | O_CLOEXEC);
    if (in < 0)
        return errno;
    char buf[65536];
    int err = 0;
    for (;;) {
        ssize_t k = read(in, buf, sizeof buf);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            err = k < 0 ? errno : 0;
            break;
        }
        for (ssize_t off = 0; off < k && !err;) {
            ssize_t w = write(to, buf + off, (size_t)(k - off));
            if (w < 0 && errno == EINTR)
                continue;
            if (w <= 0)
                err = w < 0 ? errno : EIO;
            else
                off += w;
        }
        if (err)
            break;
    }
    close(in);
    return err;
}

static int draw_plot(const struct run_opts *o, struct plot_job *pj, const char *trace,
                     const struct ncp_rt_stats *lat)
{
    if (write_latency(pj->side, lat)) {
        fprintf(stderr, "cnc-run run: --plot: cannot write %s: %s\n", pj->side, strerror(errno));
        return -1;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        execl("/usr/bin/python3", "python3", pj->script, trace, pj->png, pj->side, "--title",
              o->prog, (char *)NULL);
        _exit(127);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "cnc-run run: plotting failed: %s exited %d (its message above)\n",
                pj->script, WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st));
        return -1;
    }
    int err = copy_file(pj->png, pj->out.fd);
    if (!err)
        err = ncp_outfile_commit(&pj->out);
    if (err) {
        fprintf(stderr, "cnc-run run: cannot write %s: %s\n", o->plot, strerror(err));
        return -1;
    }
    fprintf(stderr, "cnc-run run: wrote %s\n", o->plot);
    return 0;
}

/* SIGINT/SIGTERM: a controlled stop along the path, then the summary. */
static atomic_int run_signal; /* lock-free: the handler may store it */

static void on_signal(int sig)
{
    run_signal = sig;
}

static int run_stop_asked(void *ctx)
{
    (void)ctx;
    return run_signal != 0;
}

/* The parameter file again when the run changed it (vars: as read). */
static int save_vars(const struct ncp_machine_cfg *cfg, const struct ncp_var_file *vars,
                     const struct ncp_var_file *out)
{
    int changed = 0;
    for (int k = 1; k < NCP_VAR_PARAMS && !changed; k++)
        changed = vars->listed[k] && vars->value[k] != out->value[k];
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (!changed || ncp_var_file_write(cfg->op.parameter_file, out, &d) == NCP_OK)
        return 0;
    fprintf(stderr, "cnc-run run: error: %s ([RS274NGC] PARAMETER_FILE)\n", d.msg);
    return -1;
}

/* The tool table after the run, written back whole when its G10 L1, L10 or
 * L11 changed it (as serve does after each job): 0, or -1 said on stderr. */
static int save_tools(const char *path, const struct ncp_analyzer *base,
                      const struct ncp_analyzer *out)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int written = 0;
    if (ncp_analyzer_save_tool_table(out, base, path, &written, &d) != NCP_OK) {
        fprintf(stderr, "cnc-run run: error: %s ([EMCIO] TOOL_TABLE)\n", d.msg);
        return -1;
    }
    if (written)
        fprintf(stderr, "cnc-run run: tool table %s written (G10 L1/L10/L11)\n", path);
    return 0;
}

/* The table as loaded (base) and the one the run's interpreter leaves
 * (out); both NULL without a tool table. -1 out of memory or unreadable. */
static int tools_open(const char *path, struct ncp_analyzer **base, struct ncp_analyzer **out)
{
    *base = *out = NULL;
    if (!path)
        return 0;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    const struct ncp_analyzer_cfg tc = { .tool_table_path = path };
    if (!(*base = ncp_analyzer_new(&tc, &d)) || !(*out = ncp_analyzer_new(NULL, &d))) {
        fprintf(stderr, "cnc-run run: error: %s: %s\n", path, d.msg);
        ncp_analyzer_free(*base);
        *base = NULL;
        return -1;
    }
    ncp_analyzer_copy_tools(*out, *base);
    return 0;
}

static int run_program(const struct run_opts *o, const struct ncp_machine_cfg *cfg,
                       const struct ncp_analyzer_cfg *acfg, const struct ncp_source *src,
                       FILE *trace, struct ncp_rt_stats *lat, const struct ncp_var_file *vars)
{
    struct ncp_var_file *vars_out = vars ? malloc(sizeof *vars_out) : NULL;
    if (vars && !vars_out)
        return RUN_FAULT;
    if (vars_out)
        *vars_out = *vars;
    struct ncp_analyzer *tools_base, *tools_out;
    if (tools_open(acfg->tool_table_path, &tools_base, &tools_out)) {
        free(vars_out);
        return RUN_USAGE;
    }
    struct ncp_analyzer_cfg with_vars = *acfg;
    with_vars.params_in = vars;
    with_vars.params_out = vars_out;
    with_vars.tools_out = tools_out;
    struct ncp_cli_interp ic = { src, with_vars, o->mode };
    int approx;
    uint32_t total = count_lines(src, &approx);
    struct ncp_nck_opts no = {
        .cfg = cfg, .interpret = ncp_cli_interpret, .interp_ctx = &ic,
        .virtual_clock = o->virtual_clock, .for_s = o->for_s,
        .feed_override = o->feed_override, .trace = trace,
        .progress = isatty(2) ? stderr : NULL,
        .total_lines = total,
        .total_approx = approx,
        .notes = stderr,
        .interrupt = &run_signal,
        .home = o->home,
        .trace_rings = o->trace_rings,
    };
    struct ncp_nck_result *res = malloc(sizeof *res);
    if (!res) {
        free(vars_out);
        ncp_analyzer_free(tools_base);
        ncp_analyzer_free(tools_out);
        return RUN_FAULT;
    }
    ncp_nck_run(&no, res);
    /* the interpreter's last values, as LinuxCNC writes them at its exit */
    int vars_failed = vars_out && save_vars(cfg, vars, vars_out) != 0;
    free(vars_out);
    if (tools_out && save_tools(acfg->tool_table_path, tools_base, tools_out) != 0)
        vars_failed = 1;
    ncp_analyzer_free(tools_base);
    ncp_analyzer_free(tools_out);
    if (res->warning[0] && !no.progress)
        fprintf(stderr, "cnc-run run: warning: %s\n", res->warning);
    int rc = ncp_cli_run_report(o->prog, cfg, res, stderr);
    if (res->trace_errno) {
        fprintf(stderr, "cnc-run run: error writing the trace%s%s: %s (the run stopped there; "
                        "the trace ends at its last whole row)\n",
                o->trace ? " " : " for --plot", o->trace ? o->trace : "",
                strerror(res->trace_errno));
        rc = rc ? rc : RUN_FAULT;
    }
    if (rc == RUN_OK && res->interrupted)
        rc = 128 + (int)run_signal;   /* as a shell reports a signal: 130, 143 */
    if (rc == RUN_OK && vars_failed)
        rc = RUN_FAULT;
    *lat = res->lat;
    free(res);
    return rc;
}

/* An output refused before the run: nothing of it is left behind. */
static int drop_outputs(struct ncp_outfile *trace_of, struct plot_job *pj, struct ncp_source *src)
{
    if (trace_of->fd >= 0)
        ncp_outfile_discard(trace_of);
    if (pj)
        plot_clean(pj);
    free(pj);
    ncp_source_close(src);
    return RUN_USAGE;
}

/* The run of a loaded machine and interpreter: the program, the outputs. */
static int run_loaded(const struct run_opts *op, const struct ncp_machine_cfg *cfg,
                      const struct ncp_analyzer_cfg *acfg, const struct ncp_var_file *vars)
{
    const struct run_opts o = *op;
    struct ncp_source src;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (ncp_source_open(&src, o.prog, &d) != NCP_OK) {
        if (d.line)
            fprintf(stderr, "%s:%u:%u: error: %s\n", o.prog, d.line, d.col ? (unsigned)d.col : 1u,
                    d.msg);
        else
            fprintf(stderr, "%s: error: %s\n", o.prog, d.msg);
        return RUN_PROGRAM;
    }
    ncp_cli_catch_input_faults(o.prog, 0);
    /* every output is opened (or refused) before anything moves */
    struct ncp_file_id ids[4];
    int n_ids = 0;
    if (src.ino) {
        ids[0] = (struct ncp_file_id){ src.dev, src.ino, "the program" };
        n_ids = 1;
    }
    n_ids = ncp_file_id_add(ids, n_ids, o.config, "the machine INI");
    n_ids = ncp_file_id_add(ids, n_ids, o.tool_table, "the tool table");
    struct ncp_outfile trace_of = { .fd = -1, .old_fd = -1 };
    struct plot_job *pj = o.plot ? calloc(1, sizeof *pj) : NULL;
    if (o.trace && !strcmp(o.trace, "-")) {
        fprintf(stderr, "cnc-run run: --trace wants a file (standard output is the summary's)\n");
        free(pj);
        ncp_source_close(&src);
        return RUN_USAGE;
    }
    if ((o.trace && ncp_outfile_open(&trace_of, o.trace, ids, n_ids, NCP_OUT_LIVE) != 0) ||
        (o.plot && (!pj || plot_prepare(pj, o.plot, ids, n_ids) != 0)))
        return drop_outputs(&trace_of, pj, &src);
    /* --plot alone still needs a trace: one in the plot's private folder */
    const char *trace_path = o.trace ? o.trace : pj ? pj->trace : NULL;
    FILE *trace = NULL;
    if (o.trace)
        trace = fdopen(trace_of.fd, "w");
    else if (pj)
        trace = fopen(pj->trace, "w");
    if (trace_path && !trace) {
        fprintf(stderr, "cnc-run run: cannot write %s: %s\n", trace_path, strerror(errno));
        return drop_outputs(&trace_of, pj, &src);
    }
    struct ncp_rt_stats *lat = calloc(1, sizeof *lat);
    int rc = lat ? run_program(&o, cfg, acfg, &src, trace, lat, vars) : RUN_FAULT;
    if (trace && fclose(trace) != 0) {
        fprintf(stderr, "cnc-run run: error writing %s: %s\n", trace_path, strerror(errno));
        rc = rc ? rc : RUN_FAULT;
    }
    trace_of.fd = -1;   /* closed with its stream */
    ncp_outfile_commit(&trace_of);
    int changed = ncp_source_changed(&src);
    if (changed) {
        fprintf(stderr, "%s: error: input changed while reading\n", o.prog);
        rc = RUN_PROGRAM;
    }
    if (lat && pj && !changed && draw_plot(&o, pj, trace_path, lat) != 0)
        rc = rc ? rc : RUN_FAULT;
    if (pj)
        plot_clean(pj);
    free(pj);
    free(lat);
    ncp_source_close(&src);
    return rc;
}

int ncp_cli_run(int argc, char **argv)
{
    struct run_opts o = { 0 };
    o.feed_override = 1.0;
    o.mode = NCP_MODE_SERIAL;
    if (parse_opts(argc, argv, &o))
        return usage(stderr), RUN_USAGE;
    ncp_cli_catch_stop_signals(on_signal);
    if (o.n_channels) {
        if (o.plot || o.home)
            return fprintf(stderr, "cnc-run run: --%s is for one program, not --channel\n",
                           o.plot ? "plot" : "home"), RUN_USAGE;
        struct ncp_cli_channel_common cc = {
            .virtual_clock = o.virtual_clock, .for_s = o.for_s,
            .feed_override = o.feed_override, .mode = o.mode, .trace = o.trace,
            .interp = { .tool_table_path = o.tool_table, .subroutine_path = o.sub_path,
                        .max_loop_iterations = o.max_loops, .m66_on_machine = 1,
                        .cancel = run_stop_asked },
            .backend = o.backend, .inject = o.inject, .seed = o.seed,
            .interrupt = &run_signal, .trace_rings = o.trace_rings,
        };
        return ncp_cli_run_channels(o.channel, o.n_channels, &cc);
    }
    struct ncp_machine_cfg cfg;
    if (load_config(&o, &cfg))
        return RUN_USAGE;
    if (!o.tool_table && cfg.op.tool_table[0])
        o.tool_table = cfg.op.tool_table;
    if (ncp_cli_check_tool_table(o.tool_table))
        return RUN_USAGE;
    /* the interpreter of the same INI: its [RS274NGC] (REMAP, folders) */
    struct ncp_analyzer_cfg acfg = { .tool_table_path = o.tool_table,
                                     .subroutine_path = o.sub_path,
                                     .max_loop_iterations = o.max_loops, .m66_on_machine = 1,
                                     .cancel = run_stop_asked };
    struct rs274_ini ini;
    char *joined = NULL;
    if (rs274_ini_machine(o.config, cfg.rs274.user_m_dirs, &ini, &acfg, &joined) ||
        dp1_interpreter_refused(&cfg, &acfg)) {
        rs274_ini_free(&ini);
        free(joined);
        return RUN_USAGE;
    }
    struct ncp_var_file *vars = NULL;
    int rc = ncp_cli_load_vars("cnc-run run", &cfg, &vars);
    if (rc)
        rc = rc == 2 ? RUN_PROGRAM : RUN_USAGE;
    else
        rc = run_loaded(&o, &cfg, &acfg, vars);
    free(vars);
    rs274_ini_free(&ini);
    free(joined);
    return rc;
}
