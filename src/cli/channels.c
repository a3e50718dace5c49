/* cnc-run run --channel: NC channels, each a whole NCK of its own (program,
 * machine INI, planner, position loop, simulated machine) in one process,
 * sharing the host's cores. The channels share no axes, so a fault in one
 * stops that channel alone and the others run on to their end; a stop
 * signal stops them all. Everything is loaded and every output opened (or
 * refused) before any channel moves. */
#include "channels.h"
#include "rs274_ini.h"
#include "inject_opts.h"
#include "machine.h"
#include "nck_run.h"
#include "outfile.h"
#include "signals.h"

#include "ncpar/config.h"
#include "ncpar/feeder.h"
#include "ncpar/nck.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CH_OK = 0, CH_USAGE = 1, CH_PROGRAM = 2, CH_FAULT = 3 };

struct channel {
    int num;
    char label[16];                 /* "chN: " */
    char spec_copy[PATH_MAX * 2];   /* prog and ini point into it */
    const char *prog, *ini;
    struct ncp_machine_cfg cfg;
    struct ncp_source src;
    int src_open;
    char trace_path[PATH_MAX];
    struct ncp_outfile trace_of;
    FILE *trace;
    struct ncp_cli_interp ic;
    struct rs274_ini rs274;         /* the INI's [RS274NGC]: ic's REMAP, folders */
    char *sub_path;
    struct ncp_nck_opts no;
    struct ncp_nck_result res;
    pthread_t thread;
    int started;
};

int ncp_cli_channel_trace_name(const char *pattern, int num, char *buf, size_t len)
{
    static const char key[] = "{channel}";
    size_t at = 0;
    int any = 0;
    for (const char *p = pattern; *p;) {
        int k;
        if (!strncmp(p, key, sizeof key - 1)) {
            k = snprintf(buf + at, len - at, "%d", num);
            p += sizeof key - 1;
            any = 1;
        } else {
            k = snprintf(buf + at, len - at, "%c", *p++);
        }
        if (k < 0 || (size_t)k >= len - at)
            return -1;
        at += (size_t)k;
    }
    if (any)
        return at < len ? 0 : -1;
    /* no key: TRACE.csv -> TRACE.chN.csv (a dot in a folder's name is no extension) */
    const char *slash = strrchr(pattern, '/');
    const char *dot = strrchr(slash ? slash + 1 : pattern, '.');
    if (!dot || dot == (slash ? slash + 1 : pattern))
        dot = pattern + strlen(pattern);
    int k = snprintf(buf, len, "%.*s.ch%d%s", (int)(dot - pattern), pattern, num, dot);
    return k >= 0 && (size_t)k < len ? 0 : -1;
}

/* "N:PROG" or "N:PROG:INI": the INI after the last colon, so that a program's
 * path may hold colons when an INI is named. */
static int parse_spec(struct channel *ch, const char *spec)
{
    char *end;
    errno = 0;
    long num = strtol(spec, &end, 10);
    if (end == spec || *end != ':' || errno || num < 0 || num >= NCP_CLI_CHANNELS_MAX)
        return fprintf(stderr, "cnc-run run: --channel '%s': wants N:PROG[:INI] with a channel "
                               "number 0..%d\n", spec, NCP_CLI_CHANNELS_MAX - 1), -1;
    if (snprintf(ch->spec_copy, sizeof ch->spec_copy, "%s", end + 1) >= (int)sizeof ch->spec_copy)
        return fprintf(stderr, "cnc-run run: --channel '%s': path too long\n", spec), -1;
    ch->num = (int)num;
    snprintf(ch->label, sizeof ch->label, "ch%d: ", ch->num);
    ch->prog = ch->spec_copy;
    char *colon = strrchr(ch->spec_copy, ':');
    if (colon) {
        *colon = 0;
        ch->ini = colon + 1;
    }
    if (!*ch->prog || (ch->ini && !*ch->ini))
        return fprintf(stderr, "cnc-run run: --channel '%s': wants N:PROG[:INI]\n", spec), -1;
    return 0;
}

static int load_channel(struct channel *ch, const struct ncp_cli_channel_common *c)
{
    ch->ic = (struct ncp_cli_interp){ &ch->src, c->interp, c->mode };
    if (ncp_cli_load_machine(ch->ini, &ch->cfg) ||
        ncp_cli_apply_inject("cnc-run run", c->inject, c->seed, &ch->cfg) ||
        rs274_ini_machine(ch->ini, ch->cfg.rs274.user_m_dirs, &ch->rs274, &ch->ic.acfg,
                          &ch->sub_path))
        return CH_USAGE;
    ch->cfg.backend = NCP_BACKEND_SIM;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (ncp_source_open(&ch->src, ch->prog, &d) != NCP_OK) {
        if (d.line)
            fprintf(stderr, "%s:%u:%u: error: %s\n", ch->prog, d.line,
                    d.col ? (unsigned)d.col : 1u, d.msg);
        else
            fprintf(stderr, "%s: error: %s\n", ch->prog, d.msg);
        return CH_PROGRAM;
    }
    ch->src_open = 1;
    return CH_OK;
}

static int open_trace(struct channel *ch, const struct ncp_cli_channel_common *c)
{
    if (!c->trace)
        return CH_OK;
    if (!strcmp(c->trace, "-") ||
        ncp_cli_channel_trace_name(c->trace, ch->num, ch->trace_path, sizeof ch->trace_path))
        return fprintf(stderr, "cnc-run run: --trace '%s': wants a file name\n", c->trace),
               CH_USAGE;
    struct ncp_file_id ids[2];
    int n_ids = 0;
    if (ch->src.ino) {
        ids[0] = (struct ncp_file_id){ ch->src.dev, ch->src.ino, "the program" };
        n_ids = 1;
    }
    n_ids = ncp_file_id_add(ids, n_ids, ch->ini, "the machine INI");
    if (ncp_outfile_open(&ch->trace_of, ch->trace_path, ids, n_ids, NCP_OUT_LIVE) != 0)
        return CH_USAGE;
    ch->trace = fdopen(ch->trace_of.fd, "w");
    if (!ch->trace)
        return fprintf(stderr, "cnc-run run: cannot write %s: %s\n", ch->trace_path,
                       strerror(errno)), CH_USAGE;
    return CH_OK;
}

static void *channel_main(void *arg)
{
    struct channel *ch = arg;
    ncp_nck_run(&ch->no, &ch->res);
    return NULL;
}

static void start_channel(struct channel *ch, const struct ncp_cli_channel_common *c,
                          int loop_priority_min)
{
    ch->no = (struct ncp_nck_opts){
        .cfg = &ch->cfg, .interpret = ncp_cli_interpret, .interp_ctx = &ch->ic,
        .virtual_clock = c->virtual_clock, .for_s = c->for_s,
        .feed_override = c->feed_override, .trace = ch->trace,
        .interrupt = c->interrupt, .label = ch->label,
        .trace_rings = c->trace_rings, .loop_priority_min = loop_priority_min,
    };
    if (pthread_create(&ch->thread, NULL, channel_main, ch) == 0) {
        ch->started = 1;
        return;
    }
    memset(&ch->res, 0, sizeof ch->res);
    ch->res.status = NCP_NCK_FAULT;
    snprintf(ch->res.diag.msg, sizeof ch->res.diag.msg, "cannot start the channel's thread");
}

/* The channel's report with "chN: " before each line: the channels' lines
 * stay apart however many there are. */
static int report_channel(struct channel *ch)
{
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    int rc = ncp_cli_run_report(ch->prog, &ch->cfg, &ch->res, mem ? mem : stderr);
    if (ch->res.warning[0])
        fprintf(mem ? mem : stderr, "warning: %s\n", ch->res.warning);
    if (ch->res.trace_errno) {
        fprintf(mem ? mem : stderr, "error writing the trace %s: %s (the run stopped there; "
                                    "the trace ends at its last whole row)\n",
                ch->trace_path, strerror(ch->res.trace_errno));
        rc = rc ? rc : CH_FAULT;
    }
    if (!mem)
        return rc;
    fclose(mem);
    for (char *line = text, *nl; line && *line; line = nl ? nl + 1 : NULL) {
        nl = strchr(line, '\n');
        fprintf(stderr, "ch%d: %.*s\n", ch->num, nl ? (int)(nl - line) : (int)strlen(line), line);
    }
    free(text);
    return rc;
}

static int finish_channel(struct channel *ch, const struct ncp_cli_channel_common *c)
{
    if (ch->started)
        pthread_join(ch->thread, NULL);
    int rc = report_channel(ch);
    if (ch->trace && fclose(ch->trace) != 0) {
        fprintf(stderr, "ch%d: cnc-run run: error writing %s: %s\n", ch->num, ch->trace_path,
                strerror(errno));
        rc = rc ? rc : CH_FAULT;
    }
    ch->trace = NULL;
    ch->trace_of.fd = -1;   /* closed with its stream */
    ncp_outfile_commit(&ch->trace_of);
    if (ncp_source_changed(&ch->src)) {
        fprintf(stderr, "ch%d: %s: error: input changed while reading\n", ch->num, ch->prog);
        rc = CH_PROGRAM;
    }
    if (rc == CH_OK && ch->res.interrupted && c->interrupt && *c->interrupt)
        rc = 128 + (int)*c->interrupt;
    return rc;
}

static void drop_channel(struct channel *ch)
{
    if (ch->trace) {
        fclose(ch->trace);
        ch->trace_of.fd = -1;   /* closed with its stream */
    }
    if (ch->trace_of.path)
        ncp_outfile_discard(&ch->trace_of);
    if (ch->src_open)
        ncp_source_close(&ch->src);
    ch->src_open = 0;
    rs274_ini_free(&ch->rs274);
    free(ch->sub_path);
    ch->sub_path = NULL;
}

/* Before anything moves: every spec, INI, program and trace, and no channel
 * number twice. The worst status of what failed, or CH_OK. */
static int prepare(struct channel *chs, const char *const *specs, int n,
                   const struct ncp_cli_channel_common *c)
{
    if (c->backend && strcmp(c->backend, "sim") != 0)
        return fprintf(stderr, "cnc-run run: --channel runs each channel on the simulated "
                               "machine (--backend sim), not '%s'\n", c->backend), CH_USAGE;
    for (int i = 0; i < n; i++) {
        chs[i].trace_of = (struct ncp_outfile){ .fd = -1, .old_fd = -1 };
        if (parse_spec(&chs[i], specs[i]))
            return CH_USAGE;
        for (int k = 0; k < i; k++)
            if (chs[k].num == chs[i].num)
                return fprintf(stderr, "cnc-run run: channel %d is given twice\n", chs[i].num),
                       CH_USAGE;
    }
    if (ncp_cli_check_tool_table(c->interp.tool_table_path))
        return CH_USAGE;
    /* all inputs before any output: a bad INI leaves no trace file behind */
    for (int i = 0; i < n; i++) {
        int rc = load_channel(&chs[i], c);
        if (rc != CH_OK)
            return rc;
    }
    for (int i = 0; i < n; i++) {
        int rc = open_trace(&chs[i], c);
        if (rc != CH_OK)
            return rc;
    }
    return CH_OK;
}

int ncp_cli_run_channels(const char *const *specs, int n, const struct ncp_cli_channel_common *c)
{
    struct channel *chs = calloc((size_t)n, sizeof *chs);
    if (!chs)
        return fprintf(stderr, "cnc-run run: out of memory\n"), CH_FAULT;
    int rc = prepare(chs, specs, n, c);
    if (rc != CH_OK) {
        for (int i = 0; i < n; i++)
            drop_channel(&chs[i]);
        free(chs);
        return rc;
    }
    char names[512] = "";
    for (int i = 0, at = 0; i < n && at < (int)sizeof names; i++) {
        int k = snprintf(names + at, sizeof names - (size_t)at, "%s%s", i ? ", " : "", chs[i].prog);
        at += k > 0 ? k : 0;
    }
    ncp_cli_catch_input_faults(names, 0);
    /* [SCHED]'s band lies below the lowest position loop of all channels:
     * no channel's soft-RT task rises above another channel's loop */
    int loop_min = 0;
    for (int i = 0; i < n; i++)
        if (chs[i].cfg.position.priority > 0 &&
            (!loop_min || chs[i].cfg.position.priority < loop_min))
            loop_min = chs[i].cfg.position.priority;
    for (int i = 0; i < n; i++)
        start_channel(&chs[i], c, loop_min);
    int worst = CH_OK;
    for (int i = 0; i < n; i++) {
        int r = finish_channel(&chs[i], c);
        worst = r > worst ? r : worst;
        if (chs[i].src_open)
            ncp_source_close(&chs[i].src);
        chs[i].src_open = 0;
        rs274_ini_free(&chs[i].rs274);
        free(chs[i].sub_path);
    }
    free(chs);
    return worst;
}
