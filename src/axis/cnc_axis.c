/* cnc-axis --axis L --config INI [--lcm-url URL] [--trace CSV]: one low-level
 * axis controller of the distributed NCK (the distributed-NCK paper). It advertises its axis,
 * waits for the HLC (cnc-run run --backend lcm), then runs the axis's
 * position loop on the simulated servo at the HLC's setpoints (ADCBI DP5), or
 * interpolating the records the HLC's planner starts (ADCBI DP4; DP3 after
 * profiling its look-ahead records; DP2 planning the HLC's blocks itself;
 * DP1 running its own NCK on the HLC's program; ADCAI's DP2 and DP3 through
 * its axis's stages below the point, its DP1 from its own ADCAI NCK's rough
 * records),
 * until the HLC says the program is done (exit 0) or something makes it stop
 * (exit 3, after a ramp to standstill). */
#include "axis.h"
#include "ncp_version.h"
#include "ncpar/num.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_FAULT = 3 };

/* the socket's receive buffer unless the LCM URL names one (bytes) */
#define LLC_RECV_BUF (4 << 20)

static struct llc *the_llc;

static void on_signal(int sig)
{
    atomic_store(&the_llc->signal, sig);
}

static void usage(FILE *f)
{
    fputs("usage: cnc-axis --axis L --config INI [--lcm-url URL] [--key-file F] [--trace CSV]\n"
          "                [--backend sim|socketcan[:IFACE]] [--clock-skew-us N] [--clock-drift-ppm P]\n"
          "One axis of the distributed NCK: advertises axis L of the machine INI over LCM,\n"
          "waits for `cnc-run run --backend lcm`, runs its position loop on the simulated\n"
          "servo at the HLC's setpoints (every servo period, DP 5) or interpolating the\n"
          "records of its planner (ADCBI DP 4; DP 3 its look-ahead records, DP 2 its\n"
          "blocks, planned here; DP 1 the program, run here with the NCK of the INI's\n"
          "[PLANNER] NCK; with NCK = adcai, DP 2-3 through this axis's ADCAI stages),\n"
          "and reports its status every period. Stops with a ramp within MAX_ACCELERATION\n"
          "when the HLC goes silent ([LCM] HEARTBEAT_TIMEOUT_MS), when MAX_LOST_PERIODS\n"
          "setpoints in a row are missing, on a following error, when its own NCK fails\n"
          "(DP 1) or when the HLC orders it.\n"
          "  --backend B   sim (default): the simulated servo of cnc-run's sim backend;\n"
          "                socketcan[:IFACE]: the axis's CiA 402 drive ([AXIS_L] NODE_ID,\n"
          "                COUNTS_PER_MM; [CAN] keys as for cnc-run), this LLC its CANopen\n"
          "                master; the drive's position at start is where the program starts\n"
          "  --key-file F  the NCK's key (default: [LCM] KEY_FILE, else\n"
          "                ~/.config/ncpar/lcm.key): every message is sealed with it, and\n"
          "                one without its seal is dropped and counted, never obeyed\n"
          "  --trace CSV   every period: t,slot,cmd,act,state,gap (seconds from the HLC's first\n"
          "                period; slot: the HLC's period played; state: ax_status_t's;\n"
          "                gap: 0 its own setpoint, 1 bridged to the next, 2 held, 3 left\n"
          "                out: the loop woke too late to play it, the servo held, 4 the\n"
          "                next setpoint late: the servo's feed-forward guessed it)\n"
          "Its periods run on the HLC's clock ([LCM] CLOCK: monotonic on one host; probe\n"
          "estimates the offset from round trips; ptp: CLOCK_REALTIME kept by phc2sys).\n"
          "  --clock-skew-us N, --clock-drift-ppm P   for tests: simulate another host's\n"
          "                clock, N us ahead of this one's CLOCK_MONOTONIC and gaining P ppm\n"
          "exit status: 0 the program is done, 1 usage or configuration, 3 stopped\n",
          f);
}

struct opts {
    const char *config, *url, *trace, *backend, *key_file;
    int axis;
    double skew_us, drift_ppm;
};

static int number(const char *opt, const char *v, double lo, double hi, double *out)
{
    char why[160];
    if (ncp_num_double(v, lo, hi, out) == 0)
        return 0;
    ncp_num_why(why, sizeof why, opt, v, lo, hi);
    return fprintf(stderr, "cnc-axis: %s\n", why), -1;
}

static int parse(int argc, char **argv, struct opts *o)
{
    static const struct option lo[] = {
        { "axis", required_argument, 0, 'a' },   { "config", required_argument, 0, 'c' },
        { "lcm-url", required_argument, 0, 'u' }, { "trace", required_argument, 0, 't' },
        { "help", no_argument, 0, 'h' },          { "backend", required_argument, 0, 'b' },
        { "clock-skew-us", required_argument, 0, 'S' },
        { "clock-drift-ppm", required_argument, 0, 'D' },
        { "key-file", required_argument, 0, 'k' },
        { 0, 0, 0, 0 },
    };
    int c;
    o->axis = -1;
    while ((c = getopt_long(argc, argv, "a:c:u:t:h", lo, NULL)) != -1) {
        switch (c) {
        case 'a': {
            const char *p = optarg[0] && !optarg[1] ? strchr(NCP_AXIS_LETTERS, optarg[0] & ~0x20)
                                                    : NULL;
            if (!p || !*p)
                return fprintf(stderr, "cnc-axis: --axis is one letter of %s, not '%s'\n",
                               NCP_AXIS_LETTERS, optarg), -1;
            o->axis = (int)(p - NCP_AXIS_LETTERS);
            break;
        }
        case 'c': o->config = optarg; break;
        case 'u': o->url = optarg; break;
        case 't': o->trace = optarg; break;
        case 'b': o->backend = optarg; break;
        case 'k': o->key_file = optarg; break;
        case 'S':
            if (number("--clock-skew-us", optarg, -1e12, 1e12, &o->skew_us) != 0)
                return -1;
            break;
        case 'D':
            if (number("--clock-drift-ppm", optarg, -1000, 1000, &o->drift_ppm) != 0)
                return -1;
            break;
        case 'h': usage(stdout); exit(0);
        default: return -1;
        }
    }
    if (optind != argc)
        return fprintf(stderr, "cnc-axis: unexpected argument '%s'\n", argv[optind]), -1;
    if (o->axis < 0 || !o->config)
        return fprintf(stderr, "cnc-axis: --axis and --config are required\n"), -1;
    return 0;
}

static int setup(struct llc *l, const struct opts *o, const struct ncp_machine_cfg *cfg)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    l->cfg = cfg;
    l->axis = o->axis;
    if (!(cfg->axis_mask & NCP_AXIS_BIT(o->axis)))
        return fprintf(stderr, "%s: error: the machine has no axis %c ([TRAJ] COORDINATES)\n",
                       o->config, NCP_AXIS_LETTERS[o->axis]), -1;
    for (int j = 0; j < o->axis; j++)
        l->slot += (cfg->axis_mask >> j) & 1u;
    l->period_ns = llround(cfg->servo_period * 1e9);
    l->hb_period_ns = cfg->lcm.heartbeat_period_ms * 1000000LL;
    l->hb_timeout_ns = cfg->lcm.heartbeat_timeout_ms * 1000000LL;
    ncp_dist_init();
    ncp_dist_ax_channel(l->ch_status, sizeof l->ch_status, o->axis, NCP_DIST_AX_STATUS);
    ncp_dist_ax_channel(l->ch_heartbeat, sizeof l->ch_heartbeat, o->axis, NCP_DIST_AX_HEARTBEAT);
    ncp_dist_ax_channel(l->ch_advert, sizeof l->ch_advert, o->axis, NCP_DIST_AX_ADVERT);
    ncp_dist_ax_channel(l->ch_resend, sizeof l->ch_resend, o->axis, NCP_DIST_AX_RESEND);
    const char *url = o->url ? o->url : cfg->lcm.url;
    struct ncp_dist_msg_opts mo;
    if (ncp_dist_msg_opts(&cfg->lcm, &mo, &d) != NCP_OK)
        return fprintf(stderr, "cnc-axis: error: %s\n", d.msg), -1;
    mo.opts.url = url;
    mo.opts.prefix = NULL;
    /* Whatever comes while the loop is stalled waits in this socket, every
     * process's traffic on the group with it (a few datagrams a period),
     * and the HLC says each time scaling advance in only 16 messages: the
     * system's default buffer (208 KiB) ran over in a 90 ms stall, and the
     * interpolator woke to play a feed hold's ramp at an advance it never
     * heard (20 to 160 um off the path). */
    mo.opts.recv_buf_default = LLC_RECV_BUF;
    if (ncp_msg_open(&l->msg, &mo.opts, &d) != NCP_OK)
        return fprintf(stderr, "cnc-axis: error: %s\n", d.msg), -1;
    /* the order llc_take expects */
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_FINE);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_HLC_HEARTBEAT);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_ACCDEC);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_SYNC);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_ROUGH);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_ACCDEC_AI);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_LA);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_INT);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_STEPS);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_PROGRAM);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_SCALE);
    ncp_msg_subscribe(l->msg, NCP_DIST_CH_AI_SCALE);
    /* each axis its own losses: the seed plus its index */
    struct ncp_msg_inject in = { cfg->lcm.inject_loss, cfg->lcm.inject_delay_us * 1000LL,
                                 (uint64_t)cfg->lcm.inject_seed + 1u + (uint64_t)o->axis };
    if (ncp_msg_set_inject(l->msg, &in) != 0)
        return fprintf(stderr, "cnc-axis: out of memory\n"), -1;
    l->clk.skew_ns = llround(o->skew_us * 1e3);
    l->clk.drift_ppm = o->drift_ppm;
    if (llc_clock_start(l, url, &d) != NCP_OK)
        return fprintf(stderr, "cnc-axis: error: clock probes: %s\n", d.msg), -1;
    if (llc_drive_open(l, o->backend) != 0)
        return -1;
    ncp_dist_rx_init(&l->rx, l->period_ns, 0);
    if (ncp_dist_recs_init(&l->recs) != 0 || llc_blocks_init(l) != 0 || llc_dp1_init(l) != 0)
        return fprintf(stderr, "cnc-axis: out of memory\n"), -1;
    /* ADCAI's stages, for DP1-DP3 (the same windows as the HLC's: the
     * same INI); without them those points are not advertised */
    if (cfg->nck == NCP_NCK_ADCAI)
        l->ai = llc_ai_new(cfg);
    if (o->trace) {
        l->tracing = 1;
        if (ncp_spsc_init(&l->trace_ring, sizeof(struct llc_row), 1 << 14) != 0)
            return fprintf(stderr, "cnc-axis: out of memory\n"), -1;
    }
    return 0;
}

static void drain_trace(struct llc *l, FILE *f)
{
    struct llc_row r;
    while (l->tracing && ncp_spsc_pop(&l->trace_ring, &r) == 0)
        fprintf(f, "%.6f,%.6f,%.6f,%.6f,%d,%d\n", (double)(r.t_ns - l->t_first) * 1e-9,
                (double)(r.slot_ns - l->t_first) * 1e-9, r.cmd, r.act, r.state, r.gap);
}

static int run_loop(struct llc *l, FILE *trace)
{
    /* its own phase: the period it plays follows from the HLC's grid and
     * the loop's schedule (llc.c), whatever the offset between them */
    l->loop.cfg = (struct ncp_rt_loop_cfg){ l->period_ns, l->cfg->position.priority,
                                            l->cfg->position.cpu, 0, llc_now() };
    l->loop.cycle = llc_cycle;
    l->loop.ctx = l;
    llc_drive_live(l);
    if (l->cfg->position.policy != SCHED_FIFO)
        l->loop.cfg.priority = 0;
    int rc = ncp_rt_loop_start(&l->loop);
    if (rc != 0)
        return fprintf(stderr, "cnc-axis: cannot start the position loop: %s\n", strerror(rc)),
               -1;
    if (l->loop.warning[0])
        fprintf(stderr, "cnc-axis %c: warning: %s\n", NCP_AXIS_LETTERS[l->axis], l->loop.warning);
    while (atomic_load(&l->loop.running)) {
        struct timespec ts = { 0, 5000000 };
        nanosleep(&ts, NULL);
        if (trace)
            drain_trace(l, trace);
    }
    ncp_rt_loop_join(&l->loop);
    if (trace)
        drain_trace(l, trace);
    return 0;
}

static int report(const struct llc *l)
{
    char ax = NCP_AXIS_LETTERS[l->axis];
    struct ncp_msg_stats st;
    ncp_msg_get_stats(l->msg, &st);
    fprintf(stderr,
            "cnc-axis %c: %llu periods, %u misses (periods left out %u); setpoints lost %u, "
            "held %u, stale %u, duplicate %u, bridged %u, reordered %u, limited to MAX_VELOCITY "
            "%u, next one late for feed-forward %u; injected loss %llu, delayed %llu\n",
            ax, (unsigned long long)l->loop.stats.cycles, (unsigned)l->loop.stats.misses,
            l->left_out,
            l->rx.lost, l->rx.held, l->rx.stale, l->rx.duplicate, l->rx.bridged,
            l->rx.reordered, l->clamped, l->ff_guessed,
            (unsigned long long)st.inject_lost, (unsigned long long)st.inject_delayed);
    /* what never reached the loop: without the key's seal, or too old */
    fprintf(stderr, "cnc-axis %c: dropped %llu messages without the key's seal, %llu older than "
                    "[LCM] MAX_AGE_MS\n",
            ax, (unsigned long long)st.auth_failed, (unsigned long long)st.stale);
    if (l->dp4 && !l->dp1ai)
        fprintf(stderr, "cnc-axis %c: DP %d: records taken %d, gaps %u, resend requests %u, "
                        "stale %u, duplicate %u, too early %u\n",
                ax, l->dp ? l->dp : 4, (int)l->recs.next, l->recs.gaps, l->resends, l->recs.stale,
                l->recs.duplicate, l->recs.early);
    if (l->dp4 && !l->dp1ai && l->dp == 2)
        fprintf(stderr, "cnc-axis %c: aborts of the HLC's: %u dropped with what this LLC's "
                        "planner made for them (%u periods stood for it to replay one)\n",
                ax, (unsigned)l->scale.voided, (unsigned)l->scale.drop_waits);
    else if (l->dp4 && !l->dp1ai)
        fprintf(stderr, "cnc-axis %c: aborts of the HLC's: %u dropped\n", ax,
                (unsigned)l->scale.voided);
    llc_ai_report(l);
    llc_dp1_ai_report(l);
    llc_clock_report(l);
    switch (l->end) {
    case LLC_END_CLOCK:
        fprintf(stderr, "cnc-axis %c: error: %s: the HLC's clock and this one are further apart "
                        "than [LCM] CLOCK_TOLERANCE_US %d; on two hosts use CLOCK = probe, or ptp "
                        "with ptp4l and phc2sys; stopped at %.4f mm\n",
                ax, l->fault, l->cfg->lcm.clock_tolerance_us, l->cmd);
        break;
    case LLC_END_PROGRAM:
        fprintf(stderr, "cnc-axis %c: error: DP 1: %s; held at %.4f mm\n", ax, l->fault, l->cmd);
        break;
    case LLC_END_DRIVE:
        fprintf(stderr, "cnc-axis %c: error: %s; the drive stops as its fault reaction says, "
                        "the other axes ramp to a standstill\n", ax, l->fault);
        break;
    case LLC_END_MISSING:
        fprintf(stderr, "cnc-axis %c: error: record %d was not here when the interpolator "
                        "needed it; ramped to a standstill at %.4f mm\n",
                ax, (int)l->missing_rec, l->cmd);
        break;
    case LLC_END_NONE:
    case LLC_END_DONE: return EXIT_OK;
    case LLC_END_HLC_STOP:
        if (l->hlc_axis)
            fprintf(stderr, "cnc-axis %c: error: the HLC ordered a stop (axis %c lost); ramped "
                            "to a standstill at %.4f mm\n", ax, l->hlc_axis, l->cmd);
        else
            fprintf(stderr, "cnc-axis %c: error: the HLC ordered a stop (its start-up failed, "
                            "see its output); ramped to a standstill at %.4f mm\n", ax, l->cmd);
        break;
    case LLC_END_HLC_SILENT:
        fprintf(stderr, "cnc-axis %c: error: the HLC went silent (no heartbeat for %d ms); "
                        "ramped to a standstill at %.4f mm\n",
                ax, l->cfg->lcm.heartbeat_timeout_ms, l->cmd);
        break;
    case LLC_END_LOST:
        fprintf(stderr, "cnc-axis %c: error: more than %d setpoints in a row lost (the HLC's "
                        "last heartbeat %lld ms before); ramped to a standstill at %.4f mm\n",
                ax, l->cfg->lcm.max_lost_periods,
                (long long)((l->lost_at_ns - l->last_hlc_ns) / 1000000), l->cmd);
        break;
    case LLC_END_FERROR:
        fprintf(stderr, "cnc-axis %c: error: following error %.4f mm exceeds FERROR %.4f mm; "
                        "ramped to a standstill\n", ax, l->fault_ferr, l->cfg->axis[l->axis].ferror);
        if (l->fault_late_ns)
            fprintf(stderr, "cnc-axis %c: its loop had woken %.1f ms late just before: the drive "
                            "held its setpoint that long while the path went on (a stall of this "
                            "host, not of the machine)\n", ax, (double)l->fault_late_ns * 1e-6);
        break;
    case LLC_END_SIGNAL:
        fprintf(stderr, "cnc-axis %c: stopped by a signal; ramped to a standstill at %.4f mm\n",
                ax, l->cmd);
        return 128 + atomic_load(&l->signal);
    }
    return EXIT_FAULT;
}

int main(int argc, char **argv)
{
    struct opts o = { 0 };
    if (argc == 2 && !strcmp(argv[1], "--version")) {
        printf("cnc-axis (ncpar) %s\n", NCP_VERSION);
        return EXIT_OK;
    }
    if (parse(argc, argv, &o) != 0)
        return usage(stderr), EXIT_USAGE;
    static struct ncp_machine_cfg cfg;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    ncp_machine_cfg_default(&cfg);
    if (ncp_machine_cfg_load(&cfg, o.config, &d) != NCP_OK) {
        fprintf(stderr, "%s:%u: error: %s\n", o.config, d.line, d.msg);
        return EXIT_USAGE;
    }
    if (o.key_file && snprintf(cfg.lcm.key_file, sizeof cfg.lcm.key_file, "%s", o.key_file) >=
                          (int)sizeof cfg.lcm.key_file)
        return fprintf(stderr, "cnc-axis: --key-file: the path is too long\n"), EXIT_USAGE;
    struct llc *l = calloc(1, sizeof *l);
    if (!l)
        return EXIT_FAULT;
    the_llc = l;
    FILE *trace = NULL;
    if (setup(l, &o, &cfg) != 0)
        return EXIT_USAGE;
    if (o.trace && !(trace = fopen(o.trace, "w"))) {
        fprintf(stderr, "cnc-axis: cannot write %s: %s\n", o.trace, strerror(errno));
        return EXIT_USAGE;
    }
    if (trace)
        fputs("t,slot,cmd,act,state,gap\n", trace);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    fprintf(stderr, "cnc-axis %c: waiting for the HLC\n", NCP_AXIS_LETTERS[o.axis]);
    if (run_loop(l, trace) != 0)
        l->end = LLC_END_SIGNAL;
    llc_clock_stop(l);
    llc_drive_close(l);
    int rc = report(l);
    llc_dp1_free(l);
    if (trace && fclose(trace) != 0)
        fprintf(stderr, "cnc-axis: error writing %s\n", o.trace);
    ncp_msg_close(l->msg);
    llc_ai_free(l->ai);
    return rc;
}
