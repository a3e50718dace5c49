/* DP1 at the LLC: the HLC names the program (one host: its path, size
 * and hash); this LLC runs the NCK on it itself, in a thread of its own,
 * on the virtual clock and the simulated machine, only for what its
 * planner emits (the tap). ADCBI: the records its planner starts. Those go, through a ring, into `own`, which the
 * interpolator runs on the HLC's period grid as at DP2, leaving each
 * standstill when the HLC's path did. The virtual clock steps the planner
 * only with its window full (or the program's end in it), so every LLC's
 * plan is the same, and that of a central run, however the threads are
 * scheduled. A full ring holds the planner thread back: the inner NCK
 * runs ahead of the position loop by at most the ring and `own`.
 * ADCAI (the INI's NCK): its chain's samples with their rough records,
 * which this axis's own stages take (dp1_ai.c). */
#include "axis.h"

#include <math.h>
#include <sched.h>
#include <signal.h>
#include <string.h>
#include <time.h>

#include "ncpar/inject.h"
#include "ncpar/nck.h"
#include "ncpar/pipeline.h"

#define TAP_RING 1024

struct llc_dp1 {
    struct llc *l;
    struct ncp_machine_cfg cfg;      /* the INI's, on the simulated machine */
    char path[256], tool_table[256], sub_path[256];
    int64_t size, hash;              /* the HLC's file's */
    struct ncp_source src;
    int src_open;
    struct ncp_analyzer_cfg acfg;
    struct ncp_spsc ring;            /* inner planner thread -> position loop */
    pthread_t th;
    int started;
    _Atomic int done, quit;          /* done: 1 ok, -1 its run failed (why says) */
    atomic_int stop;                 /* its NCK brakes and ends: this LLC is leaving */
    char why[200];
    char why_short[64];              /* as much as the status carries to the HLC */
    char label[32];
};

static void tap(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec)
{
    (void)la;
    struct llc_dp1 *p = ctx;
    while (ncp_spsc_push(&p->ring, rec) != 0 && !atomic_load(&p->quit)) {
        struct timespec ts = { 0, 200000 };
        nanosleep(&ts, NULL);
    }
}

static int interpret(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct llc_dp1 *p = ctx;
    struct ncp_run_stats st;
    memset(&st, 0, sizeof st);
    return ncp_serial_run(&p->src, &p->acfg, out, &st, d);
}

/* Why its run failed, for the HLC to report: where in the program and what. */
static void why_failed(struct llc_dp1 *p, const struct ncp_nck_result *res)
{
    char what[160];
    unsigned line = 0;
    if (!res) {
        snprintf(what, sizeof what, "out of memory");
    } else if (res->fault) {
        line = res->fault_line;
        snprintf(what, sizeof what, "its NCK's following error on %c: %.4f mm",
                 NCP_AXIS_LETTERS[res->fault_axis], res->fault_err);
    } else if (res->inject.trip) {
        line = res->inject.trip_line;
        ncp_inject_trip_text(&p->cfg.inject, &res->inject, p->cfg.servo_period, what,
                             sizeof what);
    } else {
        line = res->diag.line;
        snprintf(what, sizeof what, "%s", res->diag.msg[0] ? res->diag.msg : "its NCK stopped");
    }
    snprintf(p->why, sizeof p->why, "%s:%u: %s", p->path, line, what);
    char full[sizeof what + 32];
    snprintf(full, sizeof full, "its NCK, line %u: %s", line, what);
    llc_fault_short(p->why_short, sizeof p->why_short, full);
}

/* The file is the HLC's and opens: read here, not on the position loop (a
 * program of megabytes takes tens of milliseconds to hash). */
static int open_program(struct llc_dp1 *p)
{
    int64_t size;
    uint64_t h = ncp_dist_file_hash(p->path, &size);
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (size != p->size || h != (uint64_t)p->hash) {
        snprintf(p->why_short, sizeof p->why_short, "%s",
                 size < 0 ? "cannot read the program"
                          : "not the HLC's program (size or hash differ)");
        snprintf(p->why, sizeof p->why, "%s: %s", p->path, p->why_short);
        return -1;
    }
    if (ncp_source_open(&p->src, p->path, &d) != NCP_OK) {
        snprintf(p->why, sizeof p->why, "%s: %s", p->path, d.msg);
        llc_fault_short(p->why_short, sizeof p->why_short, p->why);
        return -1;
    }
    p->src_open = 1;
    return 0;
}

static int stop_asked(void *ctx)
{
    const struct llc_dp1 *p = ctx;
    return p->stop != 0;
}

static void *inner_main(void *arg)
{
    struct llc_dp1 *p = arg;
    if (open_program(p) != 0) {
        atomic_store(&p->done, -1);
        return NULL;
    }
    struct llc_dp1_ai *ai = p->l->dp1ai;
    struct ncp_nck_opts no = {
        .cfg = &p->cfg, .interpret = interpret, .interp_ctx = p, .virtual_clock = 1,
        .feed_override = 1.0, .label = p->label, .plan_tap = tap, .plan_tap_ctx = p,
        .adcai_tap = ai ? llc_dp1_ai_tap : NULL, .adcai_tap_ctx = ai,
        .interrupt = &p->stop,
    };
    struct ncp_nck_result *res = calloc(1, sizeof *res);
    int ok = res && ncp_nck_run(&no, res) == NCP_NCK_OK;
    if (!ok)
        why_failed(p, res);
    free(res);
    atomic_store(&p->done, ok ? 1 : -1);
    return NULL;
}

int llc_dp1_init(struct llc *l)
{
    struct llc_dp1 *p = calloc(1, sizeof *p);
    if (!p || ncp_spsc_init(&p->ring, sizeof(struct ncp_accdec), TAP_RING) != 0) {
        free(p);
        return -1;
    }
    p->l = l;
    l->dp1 = p;
    return 0;
}

void llc_dp1_free(struct llc *l)
{
    struct llc_dp1 *p = l->dp1;
    if (!p)
        return;
    if (p->started) {
        atomic_store(&p->quit, 1);
        /* its run brakes and ends as a stop signal would end it, rather
         * than going on to the program's end unwatched (seconds, for a
         * program of a million blocks); the tap no longer waits */
        p->stop = 1;
        struct ncp_accdec a;
        while (!atomic_load(&p->done)) {
            while (ncp_spsc_pop(&p->ring, &a) == 0)
                ;
            if (l->dp1ai)
                llc_dp1_ai_drain(l->dp1ai);
            struct timespec ts = { 0, 1000000 };
            nanosleep(&ts, NULL);
        }
        pthread_join(p->th, NULL);
        if (p->src_open)
            ncp_source_close(&p->src);
    }
    ncp_spsc_destroy(&p->ring);
    free(p);
    l->dp1 = NULL;
    llc_dp1_ai_free(l->dp1ai);
    l->dp1ai = NULL;
}

/* Position loop: the program message. The first one starts the NCK. */
void llc_on_program(struct llc *l, const uint8_t *b, size_t len)
{
    struct llc_dp1 *p = l->dp1;
    ncp_program_t m;
    memset(&m, 0, sizeof m);
    if (ncp_program_t_decode(b, 0, (int)len, &m) != (int)len || m.sender != NCP_DIST_HLC_ID ||
        p->started || l->end != LLC_END_NONE)
        return;
    l->dp = 1;
    memcpy(p->path, m.path, sizeof p->path - 1);
    memcpy(p->tool_table, m.tool_table, sizeof p->tool_table - 1);
    memcpy(p->sub_path, m.sub_path, sizeof p->sub_path - 1);
    p->size = m.size;
    p->hash = m.hash;
    if (l->cfg->nck != NCP_NCK_ADCAI && fabs(l->cmd) > 0.5e-6) {
        /* its records are positions from the origin its NCK starts at */
        snprintf(p->why_short, sizeof p->why_short, "axis off the origin (DP 1 starts there)");
        snprintf(p->why, sizeof p->why, "its NCK runs the program from the origin and the axis "
                 "stands at %.4f mm: bring it to 0 first, or use DP 2-5", l->cmd);
    } else if (l->cfg->nck == NCP_NCK_ADCAI &&
               (!l->ai || !(l->dp1ai = llc_dp1_ai_new(l, &p->quit)))) {
        snprintf(p->why, sizeof p->why, "cannot set up ADCAI's stages for its axis");
    } else {
        p->cfg = *l->cfg;
        p->cfg.backend = NCP_BACKEND_SIM;
        p->cfg.position.policy = p->cfg.planner.policy = p->cfg.interp.policy = SCHED_OTHER;
        p->cfg.position.priority = p->cfg.planner.priority = p->cfg.interp.priority = 0;
        p->cfg.position.cpu = p->cfg.planner.cpu = p->cfg.interp.cpu = -1;
        snprintf(p->label, sizeof p->label, "cnc-axis %c's NCK: ", NCP_AXIS_LETTERS[l->axis]);
        p->acfg.tool_table_path = p->tool_table[0] ? p->tool_table : NULL;
        p->acfg.subroutine_path = p->sub_path[0] ? p->sub_path : NULL;
        p->acfg.m66_on_machine = 1;
        p->acfg.cancel = stop_asked;   /* leaving: a long loop ends too */
        p->acfg.cancel_ctx = p;
        /* not the position loop's SCHED_FIFO, which a thread inherits */
        pthread_attr_t at;
        struct sched_param sp = { 0 };
        pthread_attr_init(&at);
        pthread_attr_setinheritsched(&at, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&at, SCHED_OTHER);
        pthread_attr_setschedparam(&at, &sp);
        p->started = pthread_create(&p->th, &at, inner_main, p) == 0;
        pthread_attr_destroy(&at);
        if (!p->started)
            snprintf(p->why, sizeof p->why, "cannot start its NCK thread");
    }
    if (!p->started) {
        l->end = LLC_END_PROGRAM;
        snprintf(l->fault, sizeof l->fault, "%s", p->why);
        snprintf(l->fault_short, sizeof l->fault_short, "%s", p->why_short);
    }
}

/* Position loop, every period: the records its NCK started, into `own`;
 * its NCK's failure stops the axis. */
void llc_dp1_cycle(struct llc *l)
{
    struct llc_dp1 *p = l->dp1;
    struct ncp_accdec a;
    union ncp_dist_rec u;
    if (l->dp1ai)
        llc_dp1_ai_cycle(l);
    while (ncp_dist_recs_level(&l->own) < NCP_DIST_RECS - 1 && ncp_spsc_pop(&p->ring, &a) == 0) {
        u.a = a;
        ncp_dist_recs_put(&l->own, l->own_n++, &u);
    }
    if (atomic_load(&p->done) < 0 && l->end == LLC_END_NONE) {
        l->end = LLC_END_PROGRAM;
        snprintf(l->fault, sizeof l->fault, "%s", p->why);
        snprintf(l->fault_short, sizeof l->fault_short, "%s", p->why_short);
    }
}

int llc_dp1_level(const struct llc *l)
{
    if (l->dp1ai)
        return llc_dp1_ai_level(l, atomic_load(&l->dp1->done) > 0);
    return ncp_dist_recs_level(&l->own);
}
