/* The loaded program's cycle time before the first cut (estimate.h). Not
 * a model of the planner: the planner, interpolator and position loop
 * themselves, on the virtual clock, on the simulated machine of the same
 * INI, so the time is the one a run at 100 % takes. What it cannot know it
 * takes as cnc-run run does: pauses and tool changes last [SIM]
 * AUTO_RESUME_S (at least 0), M66 and probes read their stand-ins. */
#include "estimate.h"

#include "ncpar/clock.h"
#include "ncpar/feeder.h"
#include "ncpar/nck.h"
#include "ncpar/pipeline.h"

#include <errno.h>
#include <sched.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>


struct nck_estimate_run {
    struct ncp_machine_cfg cfg;
    struct ncp_analyzer_cfg acfg;
    struct ncp_var_file vars;
    struct ncp_source src;
    char *text;
    char name[256];
    struct ncp_nck_result res;
    atomic_int stop;                 /* ncp_nck_opts.interrupt, the interpreter's cancel */
    atomic_int done;
    /* the service and the thread each hold one; the last to let go frees
     * it, so that a cancelled run is never waited for (run_drop) */
    atomic_int refs;
    atomic_int *live;                /* its nck_estimate's count of threads not ended */
    int64_t t0_ns, t1_ns;
    double start[NCP_AXES];          /* acfg.start_machine */
};

static int run_stopped(void *ctx)
{
    struct nck_estimate_run *r = ctx;
    return atomic_load_explicit(&r->stop, memory_order_relaxed);
}

static int interpret(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct nck_estimate_run *r = ctx;
    struct ncp_run_stats st;
    memset(&st, 0, sizeof st);
    return ncp_serial_run(&r->src, &r->acfg, out, &st, d);
}

/* SCHED_IDLE, which the threads ncp_nck_run starts inherit: the estimate
 * runs only on CPU time nothing else wants. At nice 10 its four spinning
 * virtual-clock threads still delayed the panel's E-stop ack by 0.4-0.6 s
 * (once 15 s) while a 30 MB preview was sent (tests/security/http-run
 * preview-large-estop: 2 of 4 runs; 4 ms without the estimate). */
static void lower_priority(void)
{
    const struct sched_param idle = { .sched_priority = 0 };
    if (sched_setscheduler((pid_t)syscall(SYS_gettid), SCHED_IDLE, &idle) != 0)
        errno = 0;   /* at the service's priority, then: still off its real-time path */
}

static void run_drop(struct nck_estimate_run *r)
{
    if (atomic_fetch_sub_explicit(&r->refs, 1, memory_order_acq_rel) != 1)
        return;
    ncp_source_close(&r->src);
    free(r->text);
    free(r);
}

static void *estimate_main(void *arg)
{
    struct nck_estimate_run *r = arg;
    lower_priority();
    struct ncp_nck_opts o = {
        .cfg = &r->cfg, .interpret = interpret, .interp_ctx = r, .virtual_clock = 1,
        .feed_override = 1.0, .interrupt = &r->stop, .label = "estimate: ", .quiet = 1,
    };
    ncp_nck_run(&o, &r->res);
    r->t1_ns = ncp_mono_ns();
    atomic_int *live = r->live;
    atomic_store_explicit(&r->done, 1, memory_order_release);
    run_drop(r);
    atomic_fetch_sub_explicit(live, 1, memory_order_release);
    return NULL;
}

/* The machine as the estimate runs it: the simulated one (never the
 * drives), standing where the served one stands, no timing faults, every
 * thread placed by the OS and below SCHED_FIFO (the virtual clock never
 * runs FIFO anyway), and a pause that goes on at once when the INI says
 * it waits for a signal. */
static void estimate_machine(struct ncp_machine_cfg *c, const double *joints)
{
    c->backend = NCP_BACKEND_SIM;
    ncp_inject_cfg_default(&c->inject);
    c->position = (struct ncp_rt_place){ -1, SCHED_OTHER, 0 };
    c->planner = c->position;
    c->interp = c->position;
    c->sched.strategy = NCP_SCHED_NONE;
    if (c->io.auto_resume_s < 0)
        c->io.auto_resume_s = 0;
    if (joints)
        memcpy(c->sim_start, joints, sizeof c->sim_start);
}

int nck_estimate_start(struct nck_estimate *e, const struct nck_estimate_input *in)
{
    nck_estimate_cancel(e, "a new load");
    memset(e, 0, offsetof(struct nck_estimate, live));
    struct nck_estimate_run *r = calloc(1, sizeof *r);
    char *text = r ? malloc(in->len + 1) : NULL;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (!text) {
        free(r);
        e->state = NCP_EST_FAILED;
        snprintf(e->why, sizeof e->why, "out of memory for the estimate");
        return -1;
    }
    memcpy(text, in->text, in->len);
    text[in->len] = 0;
    r->text = text;
    snprintf(r->name, sizeof r->name, "%s", in->name);
    r->cfg = *in->cfg;
    estimate_machine(&r->cfg, in->joints);
    /* a fresh interpreter of the same configuration, from the offsets and
     * coordinate system in force now */
    r->acfg = *in->acfg;
    r->acfg.resident = 0;
    r->acfg.instance = NULL;
    r->acfg.cancel = run_stopped;
    r->acfg.cancel_ctx = r;
    r->acfg.params_out = NULL;
    r->acfg.tools_out = NULL;
    ncp_var_file_init(&r->vars);
    for (int k = 1; k < NCP_VAR_PARAMS; k++)
        if (r->vars.listed[k])
            r->vars.value[k] = ncp_analyzer_param(in->interp, k);
    r->acfg.params_in = &r->vars;
    /* the program's first move starts where the served machine stands (a
     * G91 move, or one of fewer axes than the machine has, goes from there) */
    if (in->machine) {
        memcpy(r->start, in->machine, sizeof r->start);
        r->acfg.start_machine = r->start;
    }
    if (ncp_source_from_memory(&r->src, r->text, in->len, r->name, &d) != NCP_OK) {
        free(text);
        free(r);
        e->state = NCP_EST_FAILED;
        snprintf(e->why, sizeof e->why, "%s", d.msg);
        return -1;
    }
    r->t0_ns = ncp_mono_ns();
    atomic_init(&r->refs, 2);
    r->live = &e->live;
    atomic_fetch_add_explicit(&e->live, 1, memory_order_relaxed);
    if (pthread_create(&e->th, NULL, estimate_main, r) != 0) {
        atomic_fetch_sub_explicit(&e->live, 1, memory_order_relaxed);
        ncp_source_close(&r->src);
        free(text);
        free(r);
        e->state = NCP_EST_FAILED;
        snprintf(e->why, sizeof e->why, "cannot start the estimate's thread");
        return -1;
    }
    e->run = r;
    e->state = NCP_EST_RUNNING;
    return 0;
}

/* "line 12: soft limit: ..." as the run would have refused it */
static void failed(struct nck_estimate *e, const struct ncp_nck_result *res)
{
    e->state = NCP_EST_FAILED;
    if (res->diag.line)
        snprintf(e->why, sizeof e->why, "line %u: %s", res->diag.line, res->diag.msg);
    else if (res->diag.msg[0])
        snprintf(e->why, sizeof e->why, "%s", res->diag.msg);
    else
        snprintf(e->why, sizeof e->why, "the simulated run ended in a fault");
}

int nck_estimate_poll(struct nck_estimate *e)
{
    struct nck_estimate_run *r = e->run;
    if (!r || !atomic_load_explicit(&r->done, memory_order_acquire))
        return 0;
    const struct ncp_nck_result *res = &r->res;
    if (res->status != NCP_NCK_OK || res->limit_violation || res->refused) {
        failed(e, res);
    } else if (res->interrupted) {
        e->state = NCP_EST_CANCELLED;
        snprintf(e->why, sizeof e->why, "stopped");
    } else {
        e->state = NCP_EST_DONE;
        e->program_time = res->program_time;
        e->path_length = res->path_length;
        e->ferr_max = res->ferr_max;
        e->pauses = (int)res->pauses;
        memcpy(e->ext_min, res->ext_min, sizeof e->ext_min);
        memcpy(e->ext_max, res->ext_max, sizeof e->ext_max);
    }
    e->seconds = (double)(r->t1_ns - r->t0_ns) * 1e-9;
    /* not joined: its exit is left, and at SCHED_IDLE beside busy CPUs a
     * thread preempted between `done` and its return may wait seconds for
     * the CPU, while the service thread that polls answers the E-stop */
    pthread_detach(e->th);
    run_drop(r);
    e->run = NULL;
    return 1;
}

void nck_estimate_cancel(struct nck_estimate *e, const char *why)
{
    struct nck_estimate_run *r = e->run;
    if (!r)
        return;
    if (nck_estimate_poll(e))   /* it ended meanwhile: its result stands */
        return;
    /* Never waited for: at SCHED_IDLE beside busy CPUs it may take most of
     * a second to see the stop, and the thread that cancels it answers the
     * E-stop. It frees its run itself when it ends (run_drop). */
    atomic_store_explicit(&r->stop, 1, memory_order_relaxed);
    pthread_detach(e->th);
    run_drop(r);
    e->run = NULL;
    e->state = NCP_EST_CANCELLED;
    snprintf(e->why, sizeof e->why, "cancelled by %s", why);
}

void nck_estimate_free(struct nck_estimate *e)
{
    nck_estimate_cancel(e, "the NCK's end");
    /* what they borrow (the INI's strings, remaps) goes with the NCK */
    const struct timespec ms = { 0, 1000000 };
    while (atomic_load_explicit(&e->live, memory_order_acquire) > 0)
        nanosleep(&ms, NULL);
}
