/* One program from start to end (cnc-run run): the NCK's core with a single
 * program job; the position loop ends by itself once the plant has settled
 * after the program (or after --for's hold, or at a fault). */
#include "nck_int.h"
#include "job_state.h"
#include "service_state.h"
#include "ncpar/clock.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- the program checked whole, before any motion -------------------------------- */

enum precheck_end { PC_OK, PC_LIMIT, PC_PROGRAM, PC_INTERRUPTED };

struct precheck {
    struct ncp_canon_map map;
    const struct ncp_nck_opts *o;
    struct ncp_diag d;
    int failed;             /* the map refused a move: d says why */
    int stopped;            /* bounded or interrupted: the rest goes unchecked */
    int interrupted;
    double v_top;           /* no path moves faster: all axes at their limits */
    double t;               /* machine time the moves so far take at least */
    double t_bound;         /* past this the run never gets (0: no bound) */
    uint64_t blocks;
    int64_t t0, next_note;
};

/* A lower bound on the time a segment takes: blending may shorten a path a
 * little, which t_bound's margin covers. */
static double seg_time(const struct precheck *pc, const struct ncp_seg *s)
{
    if (s->kind == NCP_SEG_DWELL)
        return s->dwell;
    double v = s->traverse || s->feed <= 0 ? pc->v_top : fmin(s->feed, pc->v_top);
    return v > 0 ? s->length / v : 0;
}

/* A long check says how far it is, once a second, so that a program of a
 * billion moves does not look like a hang. */
static void note_progress(struct precheck *pc, uint32_t line)
{
    if ((pc->blocks & 1023) != 0 || !pc->o->notes)
        return;
    int64_t now = ncp_mono_ns();
    if (now < pc->next_note)
        return;
    pc->next_note = now + 1000000000LL;
    fprintf(pc->o->notes, "checking the program before motion: line %u, %llu blocks, %.1f s "
                          "of motion so far%s\n",
            line, (unsigned long long)pc->blocks, pc->t,
            pc->t_bound > 0 ? "" : " (--for SECONDS limits the check)");
    fflush(pc->o->notes);
}

static int emit_check(void *ctx, const struct ncp_cmd *cmd)
{
    struct precheck *pc = ctx;
    struct ncp_seg s;
    pc->blocks++;
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        /* a call the machine cannot act on is refused before anything moves */
        int rc = nck_check_call(cmd, &cmd->ops[i], &pc->d) ? -1
                 : ncp_canon_map_op(&pc->map, &cmd->ops[i], cmd->line, &s, &pc->d);
        while (rc == 1) {
            pc->t += seg_time(pc, &s);
            rc = ncp_canon_map_more(&pc->map, &s, &pc->d);
        }
        if (rc < 0) {
            pc->d.file = ncp_diag_file_of_tag(NCP_CMD_FILE(cmd));
            pc->failed = 1;
            return 1;
        }
    }
    if (pc->o->interrupt && *pc->o->interrupt) {
        pc->stopped = pc->interrupted = 1;
        return 1;
    }
    if (pc->t_bound > 0 && pc->t > pc->t_bound) {
        pc->stopped = 1;
        return 1;
    }
    note_progress(pc, cmd->line);
    return 0;
}

/* The program is interpreted once without motion: a soft-limit violation or
 * a program error anywhere refuses the run before the machine moves. Queue
 * busters (probes, M66) read rs274 -g's stand-in values here: this pass has
 * no machine to wait for. With
 * --for only what can run in that time is checked, with a margin: the moves
 * beyond it never run. */
static enum precheck_end precheck(const struct ncp_nck_opts *o, const double start[NCP_AXES],
                                  struct ncp_diag *d)
{
    struct precheck *pc = calloc(1, sizeof *pc);
    if (!pc)
        return PC_OK;
    pc->o = o;
    ncp_canon_map_init(&pc->map, o->cfg, start, o->feed_override);
    for (int j = 0; j < NCP_AXES; j++)
        pc->v_top += o->cfg->axis[j].max_vel * o->cfg->axis[j].max_vel;
    pc->v_top = sqrt(pc->v_top);
    pc->t_bound = o->for_s > 0 ? 2 * o->for_s + 1 : 0;
    pc->t0 = ncp_mono_ns();
    pc->next_note = pc->t0 + 1000000000LL;
    struct ncp_output out = { .ctx = pc, .emit = emit_check };
    struct ncp_diag id;
    memset(&id, 0, sizeof id);
    int rc = o->interpret(o->interp_ctx, &out, &id);
    enum precheck_end end = PC_OK;
    if (pc->interrupted || (rc != NCP_OK && o->interrupt && *o->interrupt)) {
        /* a loop the interpreter left on the same request ends here too */
        end = PC_INTERRUPTED;
    } else if (pc->failed) {
        *d = pc->d;
        end = pc->d.code == NCP_ERR_LIMIT ? PC_LIMIT : PC_PROGRAM;
    } else if (!pc->stopped && rc != NCP_OK) {
        *d = id;
        end = PC_PROGRAM;
    }
    free(pc);
    return end;
}

/* ---- the run ------------------------------------------------------------------------- */

/* How far the interpreter is, ahead of motion (a stretch that does not move
 * the machine is interpreted without a line in motion to show for it). */
static uint32_t line_read(const struct nck_core *n)
{
    return atomic_load_explicit(&n->job->line_read, memory_order_relaxed);
}

/* How far the run is in the program: percent of total_lines, an estimate's
 * held below 100 until the program ends. */
static double done_pct(const struct nck_summary *s, const struct ncp_nck_opts *o)
{
    if (!o->total_lines)
        return 0;
    double pct = 100.0 * s->line / o->total_lines;
    return o->total_approx && pct > 99 ? 99 : pct;
}

static void progress(const struct nck_core *n, const struct ncp_nck_opts *o)
{
    const struct nck_summary *s = &n->svc->sum;
    fprintf(o->progress,
            "\r  line %u/%s%u (%3.0f%%) read %u  t %.2f s  feed %.0f mm/min  max latency %.1f us  ",
            s->line, o->total_approx ? "~" : "", o->total_lines, done_pct(s, o),
            line_read(n), s->t, s->v * 60,
            (double)atomic_load(&n->cross.pub_lat_max_ns) / 1e3);
    fflush(o->progress);
}

/* The progress line's content as a line of its own, for a log. */
static void note_running(const struct nck_core *n, const struct ncp_nck_opts *o)
{
    const struct nck_summary *s = &n->svc->sum;
    fprintf(o->notes,
            "running: line %u of %s%u (%.0f%%), %.1f s of machine time; interpreted to line %u\n",
            s->line, o->total_approx ? "about " : "", o->total_lines, done_pct(s, o), s->t,
            line_read(n));
    fflush(o->notes);
}

/* [SIM] AUTO_RESUME_S < 0: a pause goes on at SIGUSR1. A count, not a flag:
 * every run in the process (one per NC channel) sees each signal once,
 * where a flag would be taken by whichever run looked first. */
static volatile sig_atomic_t usr1;
static void on_usr1(int sig)
{
    (void)sig;
    usr1++;
}

static void watch_usr1(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_usr1;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGUSR1, &sa, NULL);
}

/* --home: the program starts once the loop has homed the machine. */
struct batch_home {
    int pending, failed;
    struct ncp_diag diag;
};

static void homing_done(struct nck_core *n, const struct ncp_nck_opts *o, struct batch_home *bh)
{
    char report[1024];
    bh->pending = 0;
    if (nck_home_report(n, report, sizeof report) != 0) {
        bh->failed = 1;
        ncp_diag_set(&bh->diag, NCP_ERR_IO, 0, 0, "%s", report);
        atomic_store(&n->ctl->stop, 1);
        atomic_store(&n->cross.job_pending, 0);
        return;
    }
    if (o->notes)
        fprintf(o->notes, "%s\n", report);
    memcpy(n->job->map.pos, n->cross.home.final, sizeof n->job->map.pos);
    if (nck_job_start(n)) {
        bh->failed = 1;
        ncp_diag_set(&bh->diag, NCP_ERR_IO, 0, 0, "cannot start the interpreter thread");
        atomic_store(&n->ctl->stop, 1);
    }
    atomic_store(&n->cross.job_pending, 0);
}

/* Reads the loop's cycles until the loop has ended and its ring is empty. */
static void drain(struct nck_core *n, const struct ncp_nck_opts *o, struct batch_home *bh)
{
    int64_t last_print = 0, next_note = 0;
    sig_atomic_t usr1_seen = usr1;
    if (o->trace) {
        errno = 0;
        n->svc->sum.joints = ncp_kins_active(n->cfg);
        nck_trace_header(o->trace, n->cfg, n->svc->sum.joints, n->svc->sum.rings);
        if (ferror(o->trace))
            n->svc->sum.trace_errno = errno ? errno : EIO;
    }
    for (;;) {
        int got = nck_read_cycles(n);
        if (!got && !atomic_load(&n->cross.rt.running) && ncp_spsc_count(&n->cross.fbs) == 0)
            break;
        if (bh->pending && nck_home_finished(n))
            homing_done(n, o, bh);
        /* a trace that cannot be written (a full disk) stops the run as a
         * stop signal does: a run that was asked to be recorded is not
         * worth going on unrecorded */
        if (((o->interrupt && *o->interrupt) || n->svc->sum.trace_errno) &&
            !atomic_load(&n->ctl->stop))
            atomic_store(&n->ctl->stop, 1);
        if (usr1 != usr1_seen) {
            usr1_seen = usr1;
            atomic_fetch_add(&n->ctl->resume_go, 1);
            atomic_fetch_add(&n->ctl->tool_go, 1);
        }
        if (o->progress && ncp_mono_ns() - last_print > 200000000) {
            last_print = ncp_mono_ns();
            progress(n, o);
        } else if (!o->progress && o->notes && !o->quiet) {
            int64_t now = ncp_mono_ns();
            if (!next_note)
                next_note = now + NCP_NCK_NOTE_S * 1000000000LL;
            else if (now >= next_note) {
                next_note = now + NCP_NCK_NOTE_S * 1000000000LL;
                note_running(n, o);
            }
        }
        if (!got) {
            struct timespec ts = { 0, o->virtual_clock ? 50000 : 1000000 };
            nanosleep(&ts, NULL);
        }
    }
    if (o->progress && last_print)
        fputc('\n', o->progress);
    if (o->trace)
        nck_trace_flush(&n->svc->sum, o->trace);
}

/* "node 2: EMCY (0x082): ... (last completed block: line 7)", at the line
 * of the block in progress. */
static void backend_diag(const struct nck_core *n, const struct nck_loop_report *lr,
                         struct ncp_nck_result *res)
{
    char why[NCP_DIAG_MSG_MAX];
    n->cross.be.ops->describe_fault(&n->cross.be, why, sizeof why);
    char done[48] = "none";
    if (lr->line_done)
        snprintf(done, sizeof done, "line %u", lr->line_done);
    ncp_diag_set(&res->diag, NCP_ERR_IO, n->cross.fault_line, 0, "%.*s (last completed block: %s)",
                 (int)(sizeof res->diag.msg - 40), why, done);
    res->status = NCP_NCK_FAULT;
}

static void collect(const struct nck_core *n, struct ncp_nck_result *res)
{
    const struct nck_summary *s = &n->svc->sum;
    struct ncp_planner_stats ps;
    nck_plan_stats(n, &ps);
    struct nck_loop_report lr;
    nck_loop_report(n, &lr);
    res->program_time = lr.ended ? (double)lr.end_ns * 1e-9 : s->t;
    res->path_length = s->path;
    res->segments = ps.segments;
    res->starved = ps.starved;
    res->replans = ps.replans;
    res->ferr_max = s->ferr_max;
    res->ferr_avg = s->moving ? s->ferr_sum / (double)s->moving : 0;
    _Static_assert(NCP_AXES == sizeof res->ferr_axis_max / sizeof res->ferr_axis_max[0],
                   "result arrays follow the axis count");
    for (int j = 0; j < NCP_AXES; j++)
        res->ferr_axis_max[j] = s->ferr_axis_max[j];
    res->axis_mask = n->cfg->axis_mask;
    res->contour_max = s->contour_max;
    res->contour_avg = s->moving ? s->contour_sum / (double)s->moving : 0;
    res->underruns = lr.underruns;
    res->dry = lr.dry;
    int64_t sp_max, move_max;
    nck_planner_starts(n, &res->starts, &sp_max, &move_max);
    res->start_sp_max = (double)sp_max * 1e-9;
    res->start_move_max = (double)move_max * 1e-9;
    res->trace_dropped = lr.fb_dropped;
    res->fifo = n->cross.rt.fifo;
    memcpy(res->warning, n->cross.rt.warning, sizeof res->warning);
    res->lat = n->cross.rt.stats;
    res->for_expired = lr.for_expired;
    res->interrupted = atomic_load(&n->ctl->stop) && !lr.ended;
    res->trace_errno = n->svc->sum.trace_errno;
    res->spindle_rpm_max = s->rpm_max;
    nck_sched_summary(n, res->sched_summary, sizeof res->sched_summary);
    res->pauses = n->svc->pauses;
    for (int j = 0; j < NCP_AXES; j++) {
        res->ext_min[j] = s->rows ? s->ext_min[j] : 1;
        res->ext_max[j] = s->rows ? s->ext_max[j] : 0;
    }
    for (int k = 0; k < NCP_C__COUNT; k++) {
        res->calls_in += n->cross.calls_in[k];
        res->calls_acted += n->cross.calls_acted[k];
        res->calls_refused += n->cross.calls_refused[k];
    }
    res->inject = n->cross.inj_rep;
    ncp_inject_summary(&n->cfg->inject, &n->cross.inj_rep, res->inject_summary,
                       sizeof res->inject_summary);
    const struct nck_job *j = n->job;
    int fault = atomic_load(&n->cross.loop_fault);
    if (fault == NCK_LF_BACKEND) {
        backend_diag(n, &lr, res);
    } else if (fault == NCK_LF_FERROR) {
        res->fault = 1;
        res->fault_axis = n->cross.fault_axis;
        res->fault_err = n->cross.fault_err;
        res->fault_line = n->cross.fault_line;
        res->status = NCP_NCK_FAULT;
    } else if (fault == NCK_LF_JOINT) {
        ncp_diag_set(&res->diag, NCP_ERR_LIMIT, n->cross.fault_line, 0,
                     "joint limit: the %c joint was commanded to %.4f, beyond [%.4f, %.4f]; "
                     "servo stopped", NCP_AXIS_LETTERS[n->cross.fault_axis], n->cross.fault_err,
                     n->cfg->joint[n->cross.fault_axis].min_limit, n->cfg->joint[n->cross.fault_axis].max_limit);
        res->status = NCP_NCK_FAULT;
    } else if (n->cross.inj_rep.trip) {
        /* a miss limit stopped the machine along the path */
        res->status = NCP_NCK_FAULT;
    } else if (lr.for_expired || res->interrupted) {
        /* the interpreter was cut short by us: its "stopped" is no program error */
    } else if (j->map_failed || j->rc != NCP_OK) {
        res->diag = j->map_failed ? j->map_diag : j->diag;
        /* a soft limit the map found is the machine's; a loop limit the
         * interpreter hit is the program's */
        res->status = j->map_failed && res->diag.code == NCP_ERR_LIMIT ? NCP_NCK_FAULT
                                                                       : NCP_NCK_PROGRAM_ERROR;
    }
}

/* Where the program starts: --home leaves the homed axes at HOME. */
static const double *after_home(const struct nck_core *n, const struct ncp_nck_opts *o,
                                double at[NCP_AXES])
{
    memcpy(at, n->start, sizeof n->start);
    unsigned mask = o->home ? nck_home_all_mask(o->cfg) : 0;
    for (int j = 0; j < NCP_AXES; j++)
        if (mask & NCP_AXIS_BIT(j))
            at[j] = o->cfg->axis[j].home;
    return at;
}

int ncp_nck_run(const struct ncp_nck_opts *o, struct ncp_nck_result *res)
{
    struct batch_home bh;
    double from[NCP_AXES];
    memset(&bh, 0, sizeof bh);
    memset(res, 0, sizeof res[0]);
    ncp_rt_stats_reset(&res->lat);
    struct nck_core *n = calloc(1, sizeof *n);
    if (!n || nck_core_alloc(n)) {
        free(n);
        snprintf(res->diag.msg, sizeof res->diag.msg, "cannot set up the runtime");
        return res->status = NCP_NCK_FAULT;
    }
    n->plan_override = o->feed_override > 0 ? o->feed_override : 1.0;
    n->for_s = o->for_s;
    n->ctl = o->ctl;
    n->label = o->label ? o->label : "";
    n->quiet = o->quiet;
    enum precheck_end pre = PC_OK;
    struct ncp_nck_setup setup = { .cfg = o->cfg, .virtual_clock = o->virtual_clock,
                                   .trace = o->trace, .trace_rings = o->trace_rings,
                                   .loop_priority_min = o->loop_priority_min,
                                   .plan_tap = o->plan_tap, .plan_tap_ctx = o->plan_tap_ctx,
                                   .adcai_tap = o->adcai_tap, .adcai_tap_ctx = o->adcai_tap_ctx };
    /* the soft limits are checked from where the machine is, before it moves:
     * the backend reports that as it starts */
    if (nck_start(n, &setup, 1, &res->diag)) {
        if (!res->diag.code)
            res->diag.code = NCP_ERR_IO;
        res->status = NCP_NCK_FAULT;
    } else if ((pre = precheck(o, after_home(n, o, from), &res->diag)) != PC_OK) {
        res->limit_violation = pre == PC_LIMIT;
        res->refused = pre == PC_PROGRAM;
        res->interrupted = pre == PC_INTERRUPTED;
        res->status = pre == PC_LIMIT ? NCP_NCK_FAULT
                      : pre == PC_PROGRAM ? NCP_NCK_PROGRAM_ERROR : NCP_NCK_OK;
    } else {
        if (o->cfg->io.auto_resume_s < 0)
            watch_usr1();
        n->job->kind = NCK_JOB_PROGRAM;
        n->job->interpret = o->interpret;
        n->job->interp_ctx = o->interp_ctx;
        if (o->home) {
            bh.pending = 1;
            atomic_store(&n->cross.job_pending, 1);
            nck_home_request(n, nck_home_all_mask(o->cfg));
        }
        if ((!o->home && nck_job_start(n)) || nck_start_loop(n, &res->diag)) {
            snprintf(res->diag.msg, sizeof res->diag.msg, "cannot set up the runtime");
            res->status = NCP_NCK_FAULT;
        } else {
            if (n->cross.rt.warning[0] && o->progress)
                fprintf(o->progress, "warning: %s\n", n->cross.rt.warning);
            drain(n, o, &bh);
        }
    }
    nck_finish(n);
    if (res->status == NCP_NCK_OK && pre == PC_OK)
        collect(n, res);
    if (bh.failed && !(o->interrupt && *o->interrupt)) {
        res->home_failed = 1;
        res->interrupted = 0;
        res->diag = bh.diag;
        res->status = NCP_NCK_FAULT;
    }
    nck_release(n);
    nck_core_free(n);
    free(n);
    return res->status;
}
