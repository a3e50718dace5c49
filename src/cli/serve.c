/* cnc-run serve: the NCK as a long-running service on LCM. Options, the
 * machine INI, signals; the service itself is ncp_nck_serve (src/nck/). */
#include "serve.h"
#include "backend_opts.h"
#include "datadir.h"
#include "channels.h"
#include "inject_opts.h"
#include "key_opts.h"
#include "outfile.h"
#include "rs274_ini.h"
#include "machine.h"
#include "signals.h"
#include "userdata.h"

#include "ncpar/backend.h"
#include "ncpar/http.h"
#include "ncpar/nck.h"

#include "ncpar/num.h"

#include <ctype.h>
#include <getopt.h>
#include <unistd.h>
#include <signal.h>
#include <sys/stat.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { SERVE_OK = 0, SERVE_USAGE = 1, SERVE_BAD_INPUT = 2, SERVE_FAULT = 3 };

static volatile sig_atomic_t stop_signal;

static void on_signal(int sig)
{
    stop_signal = sig;
}

static int stop_requested(void *ctx)
{
    (void)ctx;
    return stop_signal != 0;
}

static void ready(void *ctx, const char *prefix)
{
    (void)ctx;
    fprintf(stderr, "cnc-run serve: listening on %sCMD (status, events and acks on %sSTATUS, "
                    "%sEVENT, %sACK)\n", prefix, prefix, prefix, prefix);
}

static void usage(FILE *f)
{
    fputs("usage: cnc-run serve [--config INI] [--lcm-url URL] [--prefix P] [--key-file F]\n"
          "                     [--backend sim|socketcan[:IFACE]|lcm] [--dp N]\n"
          "                     [--clock real|virtual] [--trace CSV] [--mode serial|det|att]\n"
          "                     [--tool-table FILE] [--subroutine-path DIR[:DIR...]]\n"
          "                     [--inject SPEC[,SPEC...]] [--seed N]\n"
          "                     [--http [ADDR:]PORT [--http-readonly] [--web DIR]]\n"
          "Runs the NCK as a service on the simulated machine, CiA 402 drives or\n"
          "distributed axes: it\n"
          "holds the axes where they are and waits for commands on LCM (cnc-ctl is its\n"
          "command-line client).\n"
          "  --config INI        machine INI (default: built-in 3-axis mill); [LCM] URL,\n"
          "                      CHANNEL_PREFIX (NCP_) and STATUS_HZ (50) are read from it,\n"
          "                      [RS274NGC] (REMAP, USER_M_PATH...) as run's. --ini INI\n"
          "                      is the same as --config.\n"
          "                      An INI of [CHANNEL_n] sections (n 0..15, CONFIG = machine\n"
          "                      INI, relative to its folder) serves one NCK per NC channel;\n"
          "                      LCM messages carry the channel (cnc-ctl --channel N), [LCM]\n"
          "                      is the lowest channel's, --trace names a file per channel\n"
          "                      as cnc-run run --channel's; a shutdown stops every channel.\n"
          "                      [CHANNEL_n] BACKEND = sim|socketcan[:IFACE]|lcm and DP give\n"
          "                      each channel its own backend (no two on one CAN interface\n"
          "                      or LCM URL). An E-stop stops every channel (one E-stop\n"
          "                      chain); a channel's fault stops the others along their\n"
          "                      paths; reset is each channel's own\n"
          "  --lcm-url URL       LCM URL (default: the INI's, else $LCM_DEFAULT_URL, else\n"
          "                      udpm://239.255.76.67:7667?ttl=0)\n"
          "  --prefix P          channel prefix (channels PCMD, PACK, PSTATUS, PEVENT)\n"
          "  --backend sim       the simulated machine (default: the INI's [EMCMOT] BACKEND,\n"
          "                      else sim)\n"
          "  --backend socketcan[:IFACE]  CiA 402 drives in CSP mode over SocketCAN\n"
          "                      ([CAN] INTERFACE; docs/integrator.md); real clock only.\n"
          "                      E-stop: Quick Stop on every drive, then\n"
          "                      Disable Voltage once at rest; reset: fault reset, back\n"
          "                      to Operation enabled where the axes stand; a drive's\n"
          "                      fault or EMCY is state fault with its code and meaning\n"
          "  --backend lcm       the distributed NCK: one `cnc-axis` per axis of the INI on\n"
          "                      the same LCM URL and key (docs/distributed.md); real clock\n"
          "                      only. Served at ADCBI DP 5, 4, 3, 2 and ADCAI DP 4, 3, 2\n"
          "                      (DP 1, where each LLC runs the program, is refused). An LLC\n"
          "                      lost or stopped on its own is state fault naming its axis,\n"
          "                      the others held; E-stop holds every LLC's command where\n"
          "                      it is (their heartbeat watch stops them if serve dies)\n"
          "  --dp N              distribution point (default: the INI's [LCM] DP, 5)\n"
          "  --key-file F        the key every command must be sealed with (default: [LCM]\n"
          "                      KEY_FILE, else ~/.config/ncpar/lcm.key); made (32 random\n"
          "                      bytes, mode 0600) when missing; refused when group or\n"
          "                      others may read it. Give clients a copy\n"
          "                      (docs/security.md)\n"
          "  --clock virtual     simulated clock: as fast as the CPU allows while moving,\n"
          "                      real time while idle\n"
          "  --trace CSV         per-cycle trace of the whole service life; the last run's\n"
          "                      trace is kept as CSV.1\n"
          "  --inject SPECS      timing faults in the position loop, as cnc-run run's;\n"
          "  --seed N            their seed\n"
          "  --http [ADDR:]PORT  the operator's panel in a browser at http://ADDR:PORT/\n"
          "                      (ADDR: numeric, default 127.0.0.1; [::1] for IPv6); the\n"
          "                      URL printed at start carries the token commands need\n"
          "  --http-readonly     the panel shows the status but takes no commands\n"
          "  --web DIR           the panel's files (default: web/ beside cnc-run, else\n"
          "                      share/ncpar/web/ of its install prefix)\n"
          "SIGINT/SIGTERM: a controlled stop along the path, then shutdown.\n"
          "exit status: 0 ok, 1 usage or set-up, 2 a malformed [RS274NGC] PARAMETER_FILE,\n"
          "3 a fault happened while serving\n",
          f);
    if (!ncp_http_available())
        fputs("(--http is missing: this cnc-run was built without libwebsockets)\n", f);
}

struct serve_args {
    const char *config, *url, *prefix, *trace, *tool_table, *sub_path, *inject, *seed;
    const char *http, *web, *key_file, *backend;
    int virtual_clock, http_readonly, dp;
    enum ncp_thread_mode mode;
};

static int parse(int argc, char **argv, struct serve_args *a)
{
    static const struct option longopts[] = {
        { "config", required_argument, 0, 'c' }, { "ini", required_argument, 0, 'N' },
        { "lcm-url", required_argument, 0, 'u' },
        { "prefix", required_argument, 0, 'P' }, { "clock", required_argument, 0, 'k' },
        { "trace", required_argument, 0, 't' }, { "mode", required_argument, 0, 'm' },
        { "tool-table", required_argument, 0, 'T' },
        { "subroutine-path", required_argument, 0, 'S' }, { "help", no_argument, 0, 'h' },
        { "inject", required_argument, 0, 'I' }, { "seed", required_argument, 0, 'R' },
        { "http", required_argument, 0, 'H' }, { "http-readonly", no_argument, 0, 'O' },
        { "web", required_argument, 0, 'W' }, { "key-file", required_argument, 0, 'K' },
        { "backend", required_argument, 0, 'b' }, { "dp", required_argument, 0, 'D' },
        { 0, 0, 0, 0 },
    };
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "c:u:P:k:t:m:T:S:hI:R:", longopts, NULL)) != -1) {
        switch (c) {
        case 'c': case 'N':
            if (ncp_cli_set_config("cnc-run serve", &a->config, optarg))
                return -1;
            break;
        case 'u': a->url = optarg; break;
        case 'P': a->prefix = optarg; break;
        case 't': a->trace = optarg; break;
        case 'T': a->tool_table = optarg; break;
        case 'S': a->sub_path = optarg; break;
        case 'I': a->inject = optarg; break;
        case 'R': a->seed = optarg; break;
        case 'H': a->http = optarg; break;
        case 'O': a->http_readonly = 1; break;
        case 'W': a->web = optarg; break;
        case 'K': a->key_file = optarg; break;
        case 'b': a->backend = optarg; break;
        case 'D': {
            double dp;
            if (ncp_num_double(optarg, 1, 5, &dp) || dp != floor(dp) || strpbrk(optarg, ".eE"))
                return fprintf(stderr, "cnc-run serve: --dp is a distribution point 1..5, not "
                                       "'%s'\n", optarg), -1;
            a->dp = (int)dp;
            break;
        }
        case 'k':
            if (strcmp(optarg, "real") != 0 && strcmp(optarg, "virtual") != 0)
                return fprintf(stderr, "cnc-run serve: --clock is real or virtual\n"), -1;
            a->virtual_clock = !strcmp(optarg, "virtual");
            break;
        case 'm':
            if (ncp_thread_mode_parse(optarg, &a->mode))
                return fprintf(stderr, "cnc-run serve: --mode is serial, det or att\n"), -1;
            break;
        case 'h': usage(stdout); exit(SERVE_OK);
        default: return -1;
        }
    }
    if (optind != argc)
        return fprintf(stderr, "cnc-run serve: unexpected argument '%s'\n", argv[optind]), -1;
    if ((a->http_readonly || a->web) && !a->http)
        return fprintf(stderr, "cnc-run serve: --http-readonly and --web need --http\n"), -1;
    return 0;
}

/* The panel's server, started before the NCK so that a port in use or a
 * build without it is a usage error before any axis is powered. Its [HTTP]
 * keys are the first channel's machine INI's. */
/* The hello's machine facts: the override sliders' ranges ([DISPLAY]
 * MAX_FEED_OVERRIDE and the spindle's MIN/MAX) and the travel (each axis's
 * soft limits, machine coordinates), as the panel reads them: it draws the
 * travel around the program and fits its view to the program. */
static void hello_facts(const struct ncp_machine_cfg *cfg, char *buf, size_t len)
{
    int n = snprintf(buf, len, ", \"limits\": {\"feed\": [0, %g], \"rapid\": [0, 100], "
                     "\"spindle\": [%g, %g]}, \"travel\": ", cfg->op.max_feed_override * 100,
                     cfg->op.min_spindle_override * 100, cfg->op.max_spindle_override * 100);
    for (int side = 0; side < 2 && n > 0 && (size_t)n < len; side++) {
        n += snprintf(buf + n, len - (size_t)n, side ? ", \"max\": {" : "{\"min\": {");
        int first = 1;
        for (int j = 0; j < NCP_AXES && n > 0 && (size_t)n < len; j++) {
            if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
                continue;
            n += snprintf(buf + n, len - (size_t)n, "%s\"%c\": %.6g", first ? "" : ", ",
                          (char)tolower((unsigned char)NCP_AXIS_LETTERS[j]),
                          side ? cfg->axis[j].max_limit : cfg->axis[j].min_limit);
            first = 0;
        }
        if (n > 0 && (size_t)n < len)
            n += snprintf(buf + n, len - (size_t)n, "}");
    }
    if (n > 0 && (size_t)n < len)
        snprintf(buf + n, len - (size_t)n, "}");
}

static int start_http(const struct serve_args *a, const struct ncp_machine_cfg *cfg,
                      const char *tool_table, struct ncp_http **out)
{
    static char exe[PATH_MAX], web[PATH_MAX], facts[1024];
    hello_facts(cfg, facts, sizeof facts);
    struct ncp_http_opts ho = { .readonly = a->http_readonly,
                                .allow_origin = cfg->http.allow_origin,
                                .allow_host = cfg->http.allow_host, .hello_extra = facts,
                                .tool_table = tool_table,
                                .history_file = cfg->op.history_file[0] ? cfg->op.history_file
                                                                        : NULL };
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return fprintf(stderr, "cnc-run serve: --http: cannot find cnc-run itself\n"), -1;
    exe[n] = 0;
    if (a->web)
        snprintf(web, sizeof web, "%s", a->web);
    else if (ncp_cli_data_dir(exe, "web", "index.html", web, sizeof web))
        return fprintf(stderr, "cnc-run serve: --http: the path of cnc-run is too long\n"), -1;
    char index[PATH_MAX + 16];
    snprintf(index, sizeof index, "%s/index.html", web);
    if (ncp_http_available() && access(index, R_OK) != 0)
        return fprintf(stderr, "cnc-run serve: --http: no panel in %s (run make)\n", web), -1;
    ho.web_root = web;
    ho.self_exe = exe;
    /* PROGRAM_PREFIX's first folder (the rest are for M100-M199 only) */
    static char progs[sizeof cfg->rs274.program_prefix];
    snprintf(progs, sizeof progs, "%s", cfg->rs274.program_prefix);
    progs[strcspn(progs, ":")] = 0;
    ho.program_dir = progs;
    if (ncp_http_parse_listen(a->http, &ho, &d) || !(*out = ncp_http_start(&ho, &d)))
        return fprintf(stderr, "cnc-run serve: %s\n", d.msg), -1;
    const char *v6 = strchr(ho.addr, ':');
    fprintf(stderr, "cnc-run serve: panel at http://%s%s%s:%d/?token=%s%s\n", v6 ? "[" : "",
            ho.addr, v6 ? "]" : "", ho.port, ncp_http_token(*out),
            a->http_readonly ? " (read-only)" : "");
    return 0;
}

/* One NC channel of the service: its machine and its trace. */
struct serve_channel {
    int num;
    const char *config;             /* NULL, or config_path or --config */
    char config_path[PATH_MAX];
    const struct ncp_cell_channel *cc;  /* its [CHANNEL_n], or NULL (one machine INI) */
    struct ncp_machine_cfg cfg;
    char trace_path[PATH_MAX];
    struct ncp_outfile trace_of;
    FILE *trace;
    /* its interpreter: the INI's [RS274NGC] over the command line's */
    struct rs274_ini ini;
    char *sub_path;
    struct ncp_analyzer_cfg acfg;
    struct ncp_var_file *vars;      /* [RS274NGC] PARAMETER_FILE read, or NULL */
    const char *tool_table;         /* --tool-table, else [EMCIO] TOOL_TABLE, or NULL */
};

/* What serve runs of the lcm backend. Each channel of a channels INI has
 * its own backend (src/backend/cell.c keeps them apart). */
static int servable(const struct serve_channel *ch, const char *cell)
{
    const struct ncp_machine_cfg *c = &ch->cfg;
    if (c->backend != NCP_BACKEND_LCM)
        return 0;
    int adcai = c->nck == NCP_NCK_ADCAI, fine = adcai ? 4 : 5;
    /* ADCBI's DP4, DP3 and DP2: each LLC's interpolator follows the loop's
     * time scaling period by period and drops what an abort drops (lcm.c,
     * src/axis/llc_scale.c; at DP2 what its own planner made before the
     * abort's DROP call, dp_block.c), so a hold, stop or E-stop stops it on
     * the path and the next job starts clean. ADCAI's DP3 and DP2: each LLC
     * plays its stages' samples at the loop's read position and starts its
     * stages again with the job after an abort (lcm_ai.c,
     * src/axis/llc_ai_play.c) */
    if (c->lcm.dp == fine || (c->lcm.dp >= 2 && c->lcm.dp <= (adcai ? 3 : 4)))
        return 0;
    char where[PATH_MAX + 64];
    if (ch->cc)
        snprintf(where, sizeof where, "%s:%u: error: [CHANNEL_%d] ", cell,
                 ch->cc->dp_line ? ch->cc->dp_line : ch->cc->line, ch->num);
    else
        snprintf(where, sizeof where, "cnc-run serve: ");
    return fprintf(stderr, "%s--backend lcm --dp %d ([PLANNER] NCK = %s) is not "
                           "served: at this point each LLC runs the program itself, and no "
                           "message takes an aborted job back out of its NCK yet: a stop or "
                           "E-stop from the seat could not end it; serve runs the distributed "
                           "NCK at %s (cnc-run run --backend lcm runs a program at DP %d)\n",
                   where, c->lcm.dp, adcai ? "adcai" : "adcbi",
                   adcai ? "ADCAI's --dp 4, 3 or 2" : "ADCBI's --dp 5, 4, 3 or 2",
                   c->lcm.dp), -1;
}

/* 0, -1 (set-up: exit 1), or -2 (a malformed parameter file or tool
 * table: exit 2) */
static int load_channel(struct serve_channel *ch, const struct serve_args *a)
{
    const struct ncp_cli_backend_opts bo = { "cnc-run serve", ch->config, a->backend, a->dp,
                                             a->url, a->key_file, a->virtual_clock };
    if (ncp_cli_load_machine(ch->config, &ch->cfg) ||
        ncp_cli_apply_inject("cnc-run serve", a->inject, a->seed, &ch->cfg) ||
        ncp_cli_apply_key_file("cnc-run serve", a->key_file, &ch->cfg))
        return -1;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (ch->cc && (ncp_cell_apply(ch->cc, &ch->cfg, &d) != NCP_OK ||
                   ncp_backend_cell_channel(ch->cc, &ch->cfg, &d) != NCP_OK))
        return fprintf(stderr, "%s:%u: error: %s (channel %d's machine: %s)\n", a->config,
                       d.line, d.msg, ch->num, ch->config), -1;
    if (ncp_cli_apply_backend(&bo, &ch->cfg) || servable(ch, a->config))
        return -1;
    ch->tool_table = a->tool_table ? a->tool_table
                     : ch->cfg.op.tool_table[0] ? ch->cfg.op.tool_table : NULL;
    if (!a->tool_table && ncp_cli_check_tool_table(ch->tool_table))
        return -1;
    ch->acfg = (struct ncp_analyzer_cfg){ .tool_table_path = ch->tool_table,
                                          .subroutine_path = a->sub_path };
    if (rs274_ini_machine(ch->config, ch->cfg.rs274.user_m_dirs, &ch->ini, &ch->acfg,
                          &ch->sub_path))
        return -1;
    if (!ch->cfg.op.history_given) {
        char why[160];
        if (ncp_cli_default_history(ch->cfg.op.history_file, sizeof ch->cfg.op.history_file,
                                    why, sizeof why))
            fprintf(stderr, "cnc-run serve: no job history ([DISPLAY] HISTORY_FILE): %s\n", why);
    }
    int rc = ncp_cli_load_vars("cnc-run serve", &ch->cfg, &ch->vars);
    return rc == 2 ? -2 : rc ? -1 : 0;
}

static void free_channels(struct serve_channel *chs, int n)
{
    for (int k = 0; chs && k < n; k++) {
        rs274_ini_free(&chs[k].ini);
        free(chs[k].sub_path);
        free(chs[k].vars);
    }
    free(chs);
}

/* the trace is a live record (outfile.h), never over an input */
static int open_trace(struct serve_channel *ch, const struct serve_args *a, int several)
{
    if (!a->trace)
        return 0;
    if (!strcmp(a->trace, "-"))
        return fprintf(stderr, "cnc-run serve: --trace wants a file\n"), -1;
    if (!several)
        snprintf(ch->trace_path, sizeof ch->trace_path, "%s", a->trace);
    else if (ncp_cli_channel_trace_name(a->trace, ch->num, ch->trace_path, sizeof ch->trace_path))
        return fprintf(stderr, "cnc-run serve: --trace '%s': name too long\n", a->trace), -1;
    struct ncp_file_id ids[2];
    int n_ids = ncp_file_id_add(ids, 0, ch->config, "the machine INI");
    n_ids = ncp_file_id_add(ids, n_ids, ch->tool_table, "the tool table");
    if (ncp_outfile_open(&ch->trace_of, ch->trace_path, ids, n_ids, NCP_OUT_LIVE) != 0)
        return -1;
    if (!(ch->trace = fdopen(ch->trace_of.fd, "w"))) {
        fprintf(stderr, "cnc-run serve: cannot write %s: %s\n", ch->trace_path, strerror(errno));
        ncp_outfile_discard(&ch->trace_of);
        return -1;
    }
    return 0;
}

/* Closes the trace; 0, or -1 after saying that writing it failed. */
static int close_trace(struct serve_channel *ch)
{
    if (!ch->trace)
        return 0;
    int rc = 0;
    if (fclose(ch->trace) != 0) {
        fprintf(stderr, "cnc-run serve: error writing %s: %s\n", ch->trace_path, strerror(errno));
        rc = -1;
    }
    ch->trace = NULL;
    ch->trace_of.fd = -1;   /* closed with its stream */
    ncp_outfile_commit(&ch->trace_of);
    return rc;
}

/* Two NC channels on one parameter file would each write their own
 * offsets over the other's: refused (the files exist by now). */
static int shared_parameter_file(const struct serve_channel *chs, int n)
{
    for (int i = 0; i < n; i++) {
        struct stat a;
        if (!chs[i].vars || stat(chs[i].cfg.op.parameter_file, &a) != 0)
            continue;
        for (int j = i + 1; j < n; j++) {
            struct stat b;
            if (chs[j].vars && stat(chs[j].cfg.op.parameter_file, &b) == 0 &&
                a.st_dev == b.st_dev && a.st_ino == b.st_ino)
                return fprintf(stderr, "cnc-run serve: error: channels %d (%s) and %d (%s) "
                               "name one [RS274NGC] PARAMETER_FILE %s: each channel keeps "
                               "its own offsets\n", chs[i].num, chs[i].config, chs[j].num,
                               chs[j].config, chs[i].cfg.op.parameter_file), 1;
        }
    }
    return 0;
}

/* --backend and --dp name every channel's backend: not beside a channels
 * INI whose [CHANNEL_n] names its own. */
static int backend_given_twice(const struct serve_args *a, const struct ncp_cell *cell)
{
    for (int k = 0; (a->backend || a->dp) && k < cell->n; k++) {
        const struct ncp_cell_channel *c = &cell->ch[k];
        if (c->backend_line || c->dp_line)
            return fprintf(stderr, "%s:%u: error: [CHANNEL_%d] %s names the channel's backend: "
                                   "--backend and --dp are for a channels INI without "
                                   "BACKEND and DP\n", a->config,
                           c->backend_line ? c->backend_line : c->dp_line, c->num,
                           c->backend_line ? "BACKEND" : "DP"), 1;
    }
    return 0;
}

/* The channels from a channels INI, or the one machine INI as channel 0;
 * NULL with *bad_input set when a channel's files are malformed. */
static struct serve_channel *load_channels(const struct serve_args *a, int *n, int *bad_input)
{
    struct ncp_cell *cell = calloc(1, sizeof *cell);
    if (!cell)
        return fprintf(stderr, "cnc-run serve: out of memory\n"), NULL;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int several = a->config ? ncp_cell_load(cell, a->config, &d) : 0;
    if (several < 0) {
        if (d.line)
            fprintf(stderr, "%s:%u: error: %s\n", a->config, d.line, d.msg);
        else
            fprintf(stderr, "%s: error: %s\n", a->config, d.msg);
    }
    if (several > 0 && backend_given_twice(a, cell))
        several = -1;
    *n = several > 0 ? cell->n : 1;
    struct serve_channel *chs = several < 0 ? NULL : calloc((size_t)*n, sizeof *chs);
    if (!chs) {
        if (several >= 0)
            fprintf(stderr, "cnc-run serve: out of memory\n");
        free(cell);
        return NULL;
    }
    for (int k = 0; k < *n; k++) {
        chs[k].num = several ? cell->ch[k].num : 0;
        if (several) {
            snprintf(chs[k].config_path, sizeof chs[k].config_path, "%s", cell->ch[k].config);
            chs[k].cc = &cell->ch[k];
        }
        chs[k].config = several ? chs[k].config_path : a->config;
    }
    for (int k = 0; k < *n; k++) {
        chs[k].trace_of.fd = -1;
        int rc = load_channel(&chs[k], a);
        if (rc) {
            *bad_input = rc == -2;
            free(cell);
            return free_channels(chs, *n), NULL;
        }
    }
    if (several) {
        const struct ncp_machine_cfg *cfgs[NCP_CELL_MAX];
        for (int k = 0; k < *n; k++)
            cfgs[k] = &chs[k].cfg;
        if (ncp_backend_cell_shared(cell, cfgs, &d) != NCP_OK) {
            fprintf(stderr, "%s:%u: error: %s\n", a->config, d.line, d.msg);
            free(cell);
            return free_channels(chs, *n), NULL;
        }
    }
    for (int k = 0; k < *n; k++)
        chs[k].cc = NULL;   /* the cell is gone after this */
    free(cell);
    if (shared_parameter_file(chs, *n))
        return free_channels(chs, *n), NULL;
    for (int k = 0; k < *n; k++) {
        if (open_trace(&chs[k], a, several)) {
            for (int i = 0; i < k; i++)
                close_trace(&chs[i]);
            return free_channels(chs, *n), NULL;
        }
    }
    return chs;
}

int ncp_cli_serve(int argc, char **argv)
{
    struct serve_args a = { 0 };
    a.mode = NCP_MODE_SERIAL;
    if (parse(argc, argv, &a))
        return usage(stderr), SERVE_USAGE;
    if (ncp_cli_check_tool_table(a.tool_table))
        return SERVE_USAGE;
    int n = 0, bad_input = 0;
    struct serve_channel *chs = load_channels(&a, &n, &bad_input);
    if (!chs)
        return bad_input ? SERVE_BAD_INPUT : SERVE_USAGE;
    /* the key before anything is powered: made when missing, refused when
     * others may read it (the service opens it again with the transport) */
    if (ncp_cli_check_key("cnc-run serve", &chs[0].cfg)) {
        for (int k = 0; k < n; k++)
            close_trace(&chs[k]);
        free_channels(chs, n);
        return SERVE_USAGE;
    }
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    struct ncp_http *http = NULL;
    if (a.http && start_http(&a, &chs[0].cfg, chs[0].tool_table, &http)) {
        for (int k = 0; k < n; k++)
            close_trace(&chs[k]);
        free_channels(chs, n);
        return SERVE_USAGE;
    }
    ncp_cli_catch_stop_signals(on_signal);
    struct ncp_nck *ncks[NCP_NCK_CHANNELS_MAX];
    int nums[NCP_NCK_CHANNELS_MAX];
    int rc = 0, made = 0;
    /* [SCHED]'s band lies below the lowest position loop of all channels */
    int loop_min = 0;
    for (int i = 0; i < n; i++)
        if (chs[i].cfg.position.priority > 0 &&
            (!loop_min || chs[i].cfg.position.priority < loop_min))
            loop_min = chs[i].cfg.position.priority;
    for (; made < n; made++) {
        struct ncp_nck_setup setup = {
            .cfg = &chs[made].cfg, .virtual_clock = a.virtual_clock, .trace = chs[made].trace,
            .mode = a.mode,
            .interp = chs[made].acfg,
            .vars = chs[made].vars,
            .loop_priority_min = loop_min,
        };
        ncks[made] = ncp_nck_new(&setup, &d);
        nums[made] = chs[made].num;
        if (!ncks[made]) {
            if (n > 1)
                fprintf(stderr, "cnc-run serve: error: channel %d (%s): %s\n", chs[made].num,
                        chs[made].config, d.msg);
            else
                fprintf(stderr, "cnc-run serve: error: %s\n", d.msg);
            rc = -2;
            break;
        }
        if (n > 1)
            fprintf(stderr, "cnc-run serve: channel %d: %s\n", chs[made].num, chs[made].config);
    }
    if (rc == 0) {
        struct ncp_nck_serve_opts so = { .hook = http ? ncp_http_hook(http) : NULL,
                                         .url = a.url, .prefix = a.prefix,
                                         .stop_requested = stop_requested, .ready = ready };
        rc = ncp_nck_serve_channels(ncks, nums, n, &so, &d);
    }
    for (int k = 0; k < made; k++)
        ncp_nck_free(ncks[k]);
    if (http) {
        struct ncp_http_stats hs;
        ncp_http_get_stats(http, &hs);
        ncp_http_stop(http);
        fprintf(stderr, "cnc-run serve: panel: %llu connections, %llu commands, %llu uploads; "
                "refused: %llu malformed, %llu unknown, %llu oversized, %llu flood, %llu "
                "without token, %llu read-only, %llu busy, %llu bad uploads\n",
                (unsigned long long)hs.connections, (unsigned long long)hs.commands,
                (unsigned long long)hs.uploads,
                (unsigned long long)hs.bad_json, (unsigned long long)hs.unknown,
                (unsigned long long)hs.oversized, (unsigned long long)hs.flood,
                (unsigned long long)hs.no_token, (unsigned long long)hs.readonly,
                (unsigned long long)hs.busy, (unsigned long long)hs.upload_bad);
    }
    for (int k = 0; k < n; k++)
        if (close_trace(&chs[k]) != 0 && rc == 0)
            rc = 1;
    free_channels(chs, n);
    if (rc == -2)
        return SERVE_FAULT;
    if (rc < 0) {
        fprintf(stderr, "cnc-run serve: error: %s\n", d.msg);
        return SERVE_USAGE;
    }
    fprintf(stderr, "cnc-run serve: shut down%s\n", rc ? " (a fault happened while serving)" : "");
    return rc ? SERVE_FAULT : SERVE_OK;
}
