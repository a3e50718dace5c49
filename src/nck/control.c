/* The serving NCK's state machine: which command fits which state, what each
 * does, and how the NCK moves on between commands (ncp_nck_poll). Runs on the
 * caller's thread only (the service thread). */
#include "control.h"
#include "job_state.h"
#include "service_state.h"
#include "ncpar/clock.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

static const char *const state_names[NCP_ST_COUNT] = {
    "idle", "running", "paused", "stepping", "mdi", "jogging", "homing", "stopping", "estop",
    "fault",
};

const char *ncp_nck_state_name(int state)
{
    return state >= 0 && state < NCP_ST_COUNT ? state_names[state] : "?";
}

int ncp_nck_state_parse(const char *name)
{
    for (int s = 0; s < NCP_ST_COUNT; s++)
        if (!strcmp(name, state_names[s]))
            return s;
    return -1;
}

static int refuse(char *reason, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int refuse(char *reason, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, len, fmt, ap);
    va_end(ap);
    return -1;
}

static void set_state(struct ncp_nck *s, int state)
{
    if (s->state != state) {
        s->state = state;
        s->changed = 1;
    }
}

static int axis_index(const char *text)
{
    if (!text[0] || text[1])
        return -1;
    const char *p = strchr("xyzabcuvw", tolower((unsigned char)text[0]));
    return p ? (int)(p - "xyzabcuvw") : -1;
}

static int all_homed(const struct ncp_nck *s)
{
    for (int j = 0; j < NCP_AXES; j++)
        if ((s->core.cfg->axis_mask & NCP_AXIS_BIT(j)) && !s->homed[j])
            return 0;
    return 1;
}

static int need_homing(const struct ncp_nck *s)
{
    return !s->core.cfg->no_force_homing && !all_homed(s);
}

/* ---- the interpreter ---------------------------------------------------------------- */

static int job_abort_asked(void *ctx)
{
    struct nck_core *n = ctx;
    return atomic_load(&n->job->abort);
}

static int interpret(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct ncp_nck *s = ctx;
    struct ncp_run_stats st;
    memset(&st, 0, sizeof st);
    if (s->core.setup.mode == NCP_MODE_SERIAL || s->run_src == &s->mdi_src)
        return ncp_serial_run(s->run_src, &s->acfg, out, &st, d);
    struct ncp_thread_map map;
    ncp_thread_map_default(&map, s->core.setup.mode, 2, 1);
    return ncp_pipeline_run(s->run_src, &map, &s->acfg, out, &st, d);
}

/* The interpreter's current point is where the machine is. */
static void sync_interp(struct ncp_nck *s)
{
    double prog[3];
    ncp_canon_map_to_program(&s->core.job->map, s->core.job->map.pos, prog);
    ncp_analyzer_set_position(s->interp, prog);
}

static int emit_state_only(void *ctx, const struct ncp_cmd *cmd)
{
    struct ncp_nck *s = ctx;
    struct ncp_seg seg;
    struct ncp_diag d;
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        nck_note_state(&s->core, &cmd->ops[i]);   /* the status shows the reset G5x too */
        int rc = ncp_canon_map_op(&s->core.job->map, &cmd->ops[i], cmd->line, &seg, &d);
        while (rc == 1)
            rc = ncp_canon_map_more(&s->core.job->map, &seg, &d);
    }
    return 0;
}

/* Lines run through the interpreter that change its state only (what the
 * status and the canon map follow), never the machine. */
static void run_state_text(struct ncp_nck *s, const char *text, const char *name)
{
    struct ncp_source src;
    struct ncp_diag d;
    if (!text[0] || ncp_source_from_memory(&src, text, strlen(text), name, &d) != NCP_OK)
        return;
    sync_interp(s);
    struct ncp_output out = { .ctx = s, .emit = emit_state_only };
    struct ncp_run_stats st;
    ncp_serial_run(&src, &s->acfg, &out, &st, &d);
    ncp_source_close(&src);
}

/* What a job, a stop or the shutdown changed of the offsets and tools (and
 * what failed to be written before), handed to the disk writer: on the
 * disk before the next command that needs it (disk_wait); a failure is the
 * operator's to know (the writer's event). */
static void persist(struct ncp_nck *s)
{
    int changed = nck_persist_changes(&s->persist, s->interp, nck_writer_again(&s->writer));
    nck_writer_persist(&s->writer, changed);
}

/* A program run's line in the job history, made here and appended by the
 * disk writer; a failure is the operator's to know, the service goes on. */
static void history_end(struct ncp_nck *s, const char *result, double program_time)
{
    char why[NCP_DIAG_MSG_MAX], line[NCK_HISTORY_LINE_MAX];
    int fault = !strcmp(result, "error") || !strcmp(result, "fault");
    int n = nck_history_end(&s->hist, result, fault ? s->error : "", program_time,
                            s->core.svc->sum.job_ferr_max, line, sizeof line, why, sizeof why);
    if (n < 0)
        nck_post(&s->core, NCP_EV_ERROR, NULL, 0, 0, "%s", why);
    else if (n > 0 && nck_writer_line(&s->writer, line, (size_t)n) != 0)
        nck_post(&s->core, NCP_EV_ERROR, NULL, 0, 0, "the job history's line for %s is lost: "
                 "%d lines wait for the disk already", s->hist.program, NCK_WRITER_LINES);
}

/* After a stop, an error or an E-stop: the interpreter's end-of-program reset
 * (G54, G17, G90, G94, spindle and coolant off, ...), as M2 would. */
static void reset_interp(struct ncp_nck *s)
{
    run_state_text(s, "M2\n", "reset");
    pthread_mutex_lock(&s->core.cross.ev_lock);
    s->core.cross.io.dir = 0;
    s->core.cross.io.mist = 0;
    s->core.cross.io.flood = 0;
    pthread_mutex_unlock(&s->core.cross.ev_lock);
    sync_interp(s);
}

/* ---- dropping what is queued --------------------------------------------------------- */

/* What a job or a drop handed to the disk writer is not all on the disk
 * yet: the state it ends in waits (a kill -9 once it shows loses nothing),
 * and so do the commands that need the disk (disk_wait); the service
 * thread answers the rest meanwhile. */
static int disk_busy(struct ncp_nck *s)
{
    return nck_writer_busy(&s->writer);
}

/* ... or it is, and the state it ends in is not taken yet (the next poll). */
static int disk_behind(struct ncp_nck *s)
{
    return s->drop == NCK_DROP_WRITE || disk_busy(s);
}

static void begin_drop(struct ncp_nck *s, int hold, int full, int after, int reset)
{
    s->machine_pause = 0;
    struct nck_core *n = &s->core;
    if (hold) {
        atomic_store(&n->cross.full_decel, full);
        ncp_nck_feed_hold(n->ctl, 1);
        s->drop = NCK_DROP_HOLD;
    } else {
        s->drop = NCK_DROP_JOB;
    }
    s->drop_after = after;
    s->drop_reset = reset;
    s->reset_after_drop = 0;
    set_state(s, NCP_ST_STOPPING);
}

static void drop_step(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    switch (s->drop) {
    case NCK_DROP_HOLD:
        if (!atomic_load(&n->cross.at_rest))
            return;
        s->drop = NCK_DROP_JOB;
        /* fall through */
    case NCK_DROP_JOB:
        atomic_store(&n->job->abort, 1);
        nck_job_join(n);
        n->job->kind = NCK_JOB_NONE;
        nck_park_planner(n);
        s->drop = NCK_DROP_PARK;
        /* fall through */
    case NCK_DROP_PARK:
        if (!nck_planner_parked(n))
            return;
        /* E-stop and faults keep the frozen setpoint (the axes coast on
         * with their drives off); a reset takes where they came to rest */
        nck_discard(n, atomic_load(&n->cross.frozen) && s->drop_after == NCP_ST_IDLE);
        s->drop = NCK_DROP_DISCARD;
        /* fall through */
    case NCK_DROP_DISCARD:
        if (!nck_discarded(n))
            return;
        nck_unpark_planner(n);
        s->drop = NCK_DROP_UNPARK;
        /* fall through */
    case NCK_DROP_UNPARK:
        if (!nck_planner_unparked(n))
            return;
        s->drop = NCK_DROP_WRITE;
        atomic_store(&n->cross.full_decel, 0);
        if (s->drop_after == NCP_ST_IDLE)
            atomic_store(&n->cross.frozen, 0);
        ncp_nck_feed_hold(n->ctl, 0);
        if (s->drop_reset)
            reset_interp(s);
        else
            sync_interp(s);
        persist(s);
        if (s->hist.open) {   /* a program run ended by the drop */
            int64_t now = atomic_load_explicit(&n->ctl->now_ns, memory_order_acquire);
            history_end(s, s->drop_after == NCP_ST_ESTOP   ? "estop"
                           : s->drop_after == NCP_ST_FAULT ? "fault"
                                                           : "stopped",
                        now > s->run_t0_ns ? (double)(now - s->run_t0_ns) * 1e-9 : 0);
        }
        /* fall through */
    case NCK_DROP_WRITE:
        if (disk_busy(s))
            return;
        s->drop = NCK_DROP_NONE;
        if (s->reset_after_drop) {
            s->reset_after_drop = 0;
            begin_drop(s, 0, 0, NCP_ST_IDLE, 0);
        } else {
            set_state(s, s->drop_after);
        }
        break;
    case NCK_DROP_NONE:
        break;
    }
}

/* ---- starting jobs ------------------------------------------------------------------ */

static int start_interp_job(struct ncp_nck *s, const struct ncp_source *src, uint32_t from,
                            int kind)
{
    struct nck_core *n = &s->core;
    sync_interp(s);
    s->run_src = src;
    n->job->kind = kind;
    n->job->interpret = interpret;
    n->job->interp_ctx = s;
    n->job->from_line = from;
    s->error[0] = 0;
    return nck_job_start(n);
}

static int start_moves(struct ncp_nck *s, const struct ncp_seg *moves, int count)
{
    struct nck_core *n = &s->core;
    n->job->kind = NCK_JOB_MOVE;
    n->job->n_moves = count;
    memcpy(n->job->moves, moves, (size_t)count * sizeof moves[0]);
    return nck_job_start(n);
}

/* ---- commands --------------------------------------------------------------------------- */

static int moving_state(int st)
{
    return st == NCP_ST_RUNNING || st == NCP_ST_PAUSED || st == NCP_ST_STEPPING ||
           st == NCP_ST_MDI || st == NCP_ST_JOGGING || st == NCP_ST_HOMING;
}

static int load_cancelled(void *ctx)
{
    struct ncp_nck *s = ctx;
    return atomic_load_explicit(&s->load_cancel, memory_order_relaxed) != NCK_CHECK_RUNS;
}

/* The check keeps nothing; an end asked for ends it at the next block, as
 * the analyzer's cancel does every few blocks (in a loop too). */
static int emit_unless_cancelled(void *ctx, const struct ncp_cmd *cmd)
{
    (void)cmd;
    return load_cancelled(ctx);
}

/* Every program error a fresh interpreter finds is refused at the load,
 * with its place, rather than after the machine has run half the part. */
static void *load_main(void *arg)
{
    struct ncp_nck *s = arg;
    struct ncp_analyzer_cfg acfg = s->acfg;
    acfg.resident = 0;
    acfg.instance = NULL;
    acfg.cancel = load_cancelled;   /* stop, E-stop, a new load: no waiting for the check */
    acfg.cancel_ctx = s;
    struct ncp_output out = { .ctx = s, .emit = emit_unless_cancelled };
    struct ncp_run_stats st;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int rc = ncp_serial_run(&s->load_src, &acfg, &out, &st, &d);
    s->load_why[0] = 0;
    if (rc != NCP_OK && rc != NCP_END)
        snprintf(s->load_why, sizeof s->load_why, "%s:%u:%u: %s",
                 d.file ? d.file : s->load_path, d.line, d.col ? d.col : 1u, d.msg);
    s->load_end_ns = ncp_mono_ns();
    atomic_store(&s->load_done, 1);
    return NULL;
}

static const char *check_end_name(int why)
{
    switch (why) {
    case NCK_CHECK_BY_STOP: return "stop";
    case NCK_CHECK_BY_ABORT: return "abort";
    case NCK_CHECK_BY_ESTOP: return "E-stop";
    case NCK_CHECK_BY_RESET: return "reset";
    case NCK_CHECK_BY_LOAD: return "a new load";
    default: return "the NCK's end";
    }
}

/* Ends a load's check early (its interpreter sees it within a few blocks),
 * and a command's wait for the disk (it is refused, not acted on). The
 * first cause asked is the one the answer names. */
static void end_check(struct ncp_nck *s, int why)
{
    int none = NCK_CHECK_RUNS;
    if (s->loading && atomic_compare_exchange_strong(&s->load_cancel, &none, why))
        s->cancel_ns = ncp_mono_ns();
    if (s->deferred && s->deferred_end == NCK_CHECK_RUNS)
        s->deferred_end = why;
}

/* The cycle time of the program just loaded, from where the machine stands
 * and the offsets in force now. */
static void start_estimate(struct ncp_nck *s)
{
    const struct nck_core *n = &s->core;
    const struct nck_estimate_input in = {
        .name = s->program, .text = s->prog.text, .len = s->prog.len, .cfg = n->cfg,
        .acfg = &s->acfg, .interp = s->interp,
        .joints = n->svc->have_fb ? n->svc->last_fb.jcmd : NULL,
        .machine = n->svc->have_fb ? n->job->map.pos : NULL,
    };
    if (nck_estimate_start(&s->est, &in))
        nck_post(&s->core, NCP_EV_ERROR, s->program, 0, 0, "estimate: %s", s->est.why);
}

/* What the estimate found, once: an event the operator and the panel see. */
static void estimate_ended(struct ncp_nck *s)
{
    const struct nck_estimate *e = &s->est;
    if (e->state == NCP_EST_DONE)
        nck_post(&s->core, NCP_EV_INFO, s->program, 0, 0,
                 "estimate: program time %.3f s, path %.3f mm, max following error %.4f mm "
                 "(simulated at 100 %% in %.2f s)", e->program_time, e->path_length, e->ferr_max,
                 e->seconds);
    else if (e->state == NCP_EST_FAILED)
        nck_post(&s->core, NCP_EV_ERROR, s->program, 0, 0, "estimate failed: %s", e->why);
}

/* The answer of a check that has ended: 0 with the program taken, or -1
 * with the reason (a program error, or what ended it). Joins its thread. */
static int check_answer(struct ncp_nck *s, char *why, size_t len)
{
    pthread_join(s->load_th, NULL);
    s->loading = 0;
    int cancel = atomic_load(&s->load_cancel);
    if (cancel || s->load_why[0]) {
        ncp_source_close(&s->load_src);
        s->rejected++;
        if (cancel == NCK_CHECK_BY_SHUTDOWN)
            return refuse(why, len, "the service is shutting down: %s not loaded (its check "
                          "was cancelled)", s->load_path);
        if (cancel)
            return refuse(why, len, "%s not loaded: its check was cancelled by %s (ended "
                          "%.2f ms after it)", s->load_path, check_end_name(cancel),
                          (double)(s->load_end_ns - s->cancel_ns) * 1e-6);
        return refuse(why, len, "%s", s->load_why);
    }
    if (s->have_prog)
        ncp_source_close(&s->prog);
    s->prog = s->load_src;
    s->have_prog = 1;
    snprintf(s->program, sizeof s->program, "%s", s->load_path);
    nck_post(&s->core, NCP_EV_INFO, s->program, 0, 0, "loaded %s", s->program);
    start_estimate(s);
    return 0;
}

/* A check asked to end and its answer kept for ncp_nck_pending: the NCK
 * takes the next load, MDI, jog or homing at once (a check sees the request
 * within a few blocks, a fraction of a millisecond). */
static void finish_ended_check(struct ncp_nck *s)
{
    s->ended_answer = 1;
    (void)check_answer(s, s->ended_why, sizeof s->ended_why);
}

static int cmd_load(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (s->state != NCP_ST_IDLE)
        return refuse(why, len, "cannot load a program while %s", ncp_nck_state_name(s->state));
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (strlen(c->text) >= sizeof s->load_path)
        return refuse(why, len, "program path longer than %zu characters",
                      sizeof s->load_path - 1);
    struct ncp_source src;
    if (ncp_source_open(&src, c->text, &d) != NCP_OK)
        return refuse(why, len, "%s: %s", c->text, d.msg);
    nck_estimate_cancel(&s->est, "a new load");
    if (s->loading) {   /* the newer load wins: the older one's answer comes first */
        end_check(s, NCK_CHECK_BY_LOAD);
        finish_ended_check(s);
    }
    s->load_src = src;
    snprintf(s->load_path, sizeof s->load_path, "%s", c->text);
    atomic_store(&s->load_done, 0);
    atomic_store(&s->load_cancel, NCK_CHECK_RUNS);
    if (pthread_create(&s->load_th, NULL, load_main, s) != 0) {
        ncp_source_close(&s->load_src);
        return refuse(why, len, "cannot start the program's check");
    }
    s->loading = 1;
    return NCP_NCK_CMD_PENDING;
}

static const char *disk_cmd_name(int kind)
{
    switch (kind) {
    case NCP_CMD_LOAD: return "load";
    case NCP_CMD_RUN: return "run";
    case NCP_CMD_MDI: return "MDI";
    default: return "files";
    }
}

/* The commands that start something new, or read the files the writer
 * writes: whatever the jobs before changed (offsets, tools, the history's
 * lines) is on the disk before they act, so a kill -9 after their answer
 * loses nothing, and cnc-ctl history reads every line. */
static int needs_disk(int kind)
{
    return kind == NCP_CMD_LOAD || kind == NCP_CMD_RUN || kind == NCP_CMD_MDI ||
           kind == NCP_CMD_FILES;
}

/* 0: the command acts now. Else it waits for the disk writer, and the
 * service thread goes on answering the rest (E-stop, stop, feed hold,
 * status): NCP_NCK_CMD_PENDING, kept and acted on by ncp_nck_pending once
 * the writer has caught up; or -1 when another command waits already
 * (one answer pending at a time, as a load's). */
static int disk_wait(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (!needs_disk(c->kind) || (!s->deferred && !disk_behind(s)))
        return 0;
    if (s->deferred || s->loading || s->ended_answer)
        return refuse(why, len, "%s: the NCK is writing to its disk and another command "
                      "waits for it: again once that one is answered", disk_cmd_name(c->kind));
    s->deferred = 1;
    s->deferred_end = NCK_CHECK_RUNS;
    s->deferred_cmd = *c;
    s->deferred_ns = ncp_mono_ns();
    s->deferred_told = 0;
    return NCP_NCK_CMD_PENDING;
}

/* The deferred command's answer: refused when a stop (or the like) ended
 * its wait, acted on once the writer has caught up. */
static int deferred_answer(struct ncp_nck *s, char *why, size_t len)
{
    const char *name = disk_cmd_name(s->deferred_cmd.kind);
    if (s->deferred_end != NCK_CHECK_RUNS) {
        s->deferred = 0;
        s->rejected++;
        return refuse(why, len, "%s not done: %s came while it waited for the disk (the "
                      "last job's history and offsets being written)", name,
                      check_end_name(s->deferred_end));
    }
    if (s->drop == NCK_DROP_WRITE)
        drop_step(s);   /* the state the job ends in, when written: the command's own */
    if (disk_behind(s)) {
        /* a disk that hangs (NFS): the operator learns why nothing answers */
        if (!s->deferred_told && ncp_mono_ns() - s->deferred_ns > 1000000000) {
            s->deferred_told = 1;
            nck_post(&s->core, NCP_EV_INFO, NULL, 0, 0, "%s waits for the disk: the last "
                     "job's history line and offsets are still being written", name);
        }
        return NCP_NCK_CMD_PENDING;
    }
    s->deferred = 0;
    return ncp_nck_command(s, &s->deferred_cmd, why, len);
}

int ncp_nck_pending(struct ncp_nck *s, char *why, size_t len)
{
    if (len)
        why[0] = 0;
    if (s->ended_answer) {
        s->ended_answer = 0;
        return refuse(why, len, "%s", s->ended_why);
    }
    if (s->deferred)
        return deferred_answer(s, why, len);
    if (!s->loading)
        return refuse(why, len, "no command is pending");
    if (!atomic_load(&s->load_done))
        return NCP_NCK_CMD_PENDING;
    return check_answer(s, why, len);
}

/* A load being checked: the commands that would use the program, or start
 * anything else, wait for its answer (a new load ends the check). */
static int waits_for_load(int kind)
{
    return kind == NCP_CMD_RUN || kind == NCP_CMD_MDI || kind == NCP_CMD_JOG ||
           kind == NCP_CMD_HOME;
}

static int cmd_run(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (s->state != NCP_ST_IDLE)
        return refuse(why, len, "cannot run while %s", ncp_nck_state_name(s->state));
    if (!s->have_prog)
        return refuse(why, len, "no program loaded (cnc-ctl load PROG)");
    if (need_homing(s))
        return refuse(why, len, "the machine is not homed (cnc-ctl home all)");
    if (c->ivalue[0] < 0)
        return refuse(why, len, "run --from-line wants a line number of 1 or more");
    /* the job has the machine to itself: an estimate still running ends
     * here (it said so if it ended just before) */
    if (nck_estimate_poll(&s->est))
        estimate_ended(s);
    nck_estimate_cancel(&s->est, "the program's run");
    s->run_t0_ns = atomic_load_explicit(&s->core.ctl->now_ns, memory_order_acquire);
    if (start_interp_job(s, &s->prog, (uint32_t)c->ivalue[0], NCK_JOB_PROGRAM))
        return refuse(why, len, "cannot start the interpreter thread");
    s->core.svc->sum.job_ferr_max = 0;
    s->core.svc->sum.job_done_s = 0;
    s->run_from_line = (uint32_t)c->ivalue[0];
    nck_history_begin(&s->hist, s->program, s->prog.text, s->prog.len,
                      s->est.state == NCP_EST_DONE ? s->est.program_time : -1);
    set_state(s, atomic_load(&s->core.job->step) ? NCP_ST_STEPPING : NCP_ST_RUNNING);
    nck_post(&s->core, NCP_EV_INFO, s->program, 0, 0, "running %s%s", s->program,
             c->ivalue[0] > 0 ? " from a line" : "");
    return 0;
}

static int cmd_mdi(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (s->state != NCP_ST_IDLE)
        return refuse(why, len, "cannot run MDI while %s", ncp_nck_state_name(s->state));
    if (need_homing(s))
        return refuse(why, len, "the machine is not homed (cnc-ctl home all)");
    size_t k = strnlen(c->text, sizeof c->text);
    if (k == 0 || memchr(c->text, '\n', k))
        return refuse(why, len, "MDI takes one non-empty line");
    memcpy(s->mdi, c->text, k);
    s->mdi[k] = '\n';
    s->mdi[k + 1] = 0;
    struct ncp_diag d;
    ncp_source_from_memory(&s->mdi_src, s->mdi, k + 1, "MDI", &d);
    if (start_interp_job(s, &s->mdi_src, 0, NCK_JOB_MDI))
        return refuse(why, len, "cannot start the interpreter thread");
    set_state(s, NCP_ST_MDI);
    return 0;
}

/* A jog is a line at the jog speed: continuous ones towards the soft limit
 * (they end there, or when stopped), incremental ones by the distance, cut
 * at the soft limit. */
static int cmd_jog(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    struct nck_core *n = &s->core;
    if (s->state != NCP_ST_IDLE)
        return refuse(why, len, "cannot jog while %s", ncp_nck_state_name(s->state));
    int j = axis_index(c->text);
    if (j < 0 || !(n->cfg->axis_mask & NCP_AXIS_BIT(j))) {
        char have[2 * NCP_AXES + 1];
        size_t k = 0;
        for (int i = 0; i < NCP_AXES; i++)
            if (n->cfg->axis_mask & NCP_AXIS_BIT(i)) {
                have[k++] = NCP_AXIS_LETTERS[i];
                have[k++] = ' ';
            }
        have[k ? k - 1 : 0] = '\0';
        return refuse(why, len, "no axis '%s' on this machine (it has %s)", c->text, have);
    }
    int dir = c->ivalue[0];
    if (dir != 1 && dir != -1)
        return refuse(why, len, "jog direction is +1 or -1, not %d", (int)dir);
    const struct ncp_axis_cfg *a = &n->cfg->axis[j];
    const char *unit = ncp_axis_rotary(j) ? "deg" : "mm";
    if (!isfinite(c->value[0]) || c->value[0] < 0)
        return refuse(why, len, "jog speed is a %s/min above 0 (0: the default), not %g", unit,
                      c->value[0]);
    if (!isfinite(c->value[1]) || c->value[1] < 0)
        return refuse(why, len, "jog distance is a %s above 0 (0: continuous), not %g", unit,
                      c->value[1]);
    double speed = c->value[0] > 0 ? c->value[0] / 60.0 : n->cfg->default_linear_vel;
    /* as a real controller: no axis jogs faster than its MAX_VELOCITY */
    if (speed > a->max_vel) {
        nck_post(n, NCP_EV_INFO, NULL, 0, 0, "jog of %c at %g %s/min, its MAX_VELOCITY, not %g",
                 NCP_AXIS_LETTERS[j], a->max_vel * 60, unit, speed * 60);
        speed = a->max_vel;
    }
    double target[NCP_AXES];
    memcpy(target, n->job->map.pos, sizeof target);
    double limit = dir > 0 ? a->max_limit : a->min_limit;
    double dist = c->value[1];
    target[j] = dist > 0 ? target[j] + dir * dist : limit;
    target[j] = dir > 0 ? fmin(target[j], limit) : fmax(target[j], limit);
    if (fabs(target[j] - n->job->map.pos[j]) < 1e-9)
        return refuse(why, len, "%c is at its soft limit %.4f", NCP_AXIS_LETTERS[j], limit);
    struct ncp_seg seg;
    n->job->step_line = 0;
    /* the loop plays feed moves at override / plan override: at 100 % the
     * jog runs at its speed (capped by the planner at the axis's limit) */
    nck_line(n, &seg, n->job->map.pos, target, speed * n->plan_override, 0);
    if (start_moves(s, &seg, 1))
        return refuse(why, len, "cannot start the jog");
    memcpy(n->job->map.pos, target, sizeof n->job->map.pos);
    s->jog_continuous = dist <= 0;
    s->jog_last_ns = ncp_mono_ns();
    set_state(s, NCP_ST_JOGGING);
    return 0;
}

/* ADCBI's DP1: each LLC runs the program itself, from its own planner, and
 * never sees the loop's homing moves or the offset homing puts between the
 * plan and the axes. */
static int own_program_lcm(const struct ncp_machine_cfg *cfg)
{
    return cfg->backend == NCP_BACKEND_LCM && cfg->nck == NCP_NCK_ADCBI && cfg->lcm.dp == 1;
}

/* Where the LLCs make their own setpoints from the HLC's stream (ADCAI's
 * DP3 and DP2, ADCBI's block-level DP4-DP2): they play the loop's own
 * setpoints while it homes, then their stream starts again where homing left
 * the axes, after an abort of nothing (lcm.c, llc.c fine_phase). */
static int lcm_restarts_after_home(const struct ncp_machine_cfg *cfg)
{
    if (cfg->backend != NCP_BACKEND_LCM)
        return 0;
    return cfg->nck == NCP_NCK_ADCAI ? cfg->lcm.dp >= 2 && cfg->lcm.dp <= 3
                                     : cfg->lcm.dp >= 2 && cfg->lcm.dp <= 4;
}

/* Homing (homing.c): `all` (or nothing) homes the axes of the HOME_SEQUENCE
 * list, letters name axes (`XZ`); either way by sequence, the position
 * loop driving the axes itself. */
static int cmd_home(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    struct nck_core *n = &s->core;
    const struct ncp_machine_cfg *cfg = n->cfg;
    if (s->state != NCP_ST_IDLE)
        return refuse(why, len, "cannot home while %s", ncp_nck_state_name(s->state));
    unsigned mask = 0;
    if (!c->text[0] || !strcasecmp(c->text, "all")) {
        mask = nck_home_all_mask(cfg);
    } else {
        for (const char *p = c->text; *p; p++) {
            char one[2] = { *p, 0 };
            int j = axis_index(one);
            if (j < 0 || !(cfg->axis_mask & NCP_AXIS_BIT(j)))
                return refuse(why, len, "home takes the machine's axis letters or all, not "
                              "'%s'", c->text);
            mask |= NCP_AXIS_BIT(j);
        }
        /* LinuxCNC's synchronised joints home only as their whole group */
        for (int j = 0; j < NCP_AXES; j++) {
            if (!(mask & NCP_AXIS_BIT(j)) || cfg->axis[j].home_sequence >= 0)
                continue;
            for (int k = 0; k < NCP_AXES; k++)
                if ((cfg->axis_mask & NCP_AXIS_BIT(k)) && !(mask & NCP_AXIS_BIT(k)) &&
                    cfg->axis[k].home_sequence == cfg->axis[j].home_sequence)
                    return refuse(why, len, "%c and %c home together (HOME_SEQUENCE %d): home "
                                  "both", NCP_AXIS_LETTERS[j], NCP_AXIS_LETTERS[k],
                                  cfg->axis[j].home_sequence);
        }
    }
    if (own_program_lcm(cfg))
        for (int j = 0; j < NCP_AXES; j++) {
            if (!(mask & NCP_AXIS_BIT(j)))
                continue;
            const struct ncp_axis_cfg *a = &cfg->axis[j];
            double at = n->svc->have_fb ? n->svc->last_fb.cmd[j] : n->start[j];
            if (a->home_search_vel != 0 || fabs(at - a->home_offset) > 1e-6)
                return refuse(why, len, "home %c: not served on --backend lcm --dp %d: the "
                              "LLCs run the program themselves and homing is the position "
                              "loop's own motion (HOME_SEARCH_VEL %g) or offset (the axis at "
                              "%.4f, HOME_OFFSET %g); home at DP 2-5",
                              NCP_AXIS_LETTERS[j], cfg->lcm.dp, a->home_search_vel, at,
                              a->home_offset);
        }
    for (int j = 0; j < NCP_AXES; j++)
        if (mask & NCP_AXIS_BIT(j))
            s->homed[j] = 0;
    n->job->step_line = 0;
    nck_home_request(n, mask);
    s->homing_axes = (int)mask;
    set_state(s, NCP_ST_HOMING);
    return 0;
}

static int cmd_override(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    double pct = c->value[0];
    if (!isfinite(pct) || pct < 0)
        return refuse(why, len, "an override is a percentage of 0 or more");
    const struct ncp_op_cfg *op = &s->core.cfg->op;
    switch (c->ivalue[0]) {
    case 0:
        /* 1e-9: "override feed 120" against 1.2 */
        if (pct > 100.0 * s->core.plan_override + 1e-9)
            return refuse(why, len, "feed override %g %% is above this machine's %g %% "
                          "([DISPLAY] MAX_FEED_OVERRIDE = %g in its INI, at most 2.0)", pct,
                          100.0 * s->core.plan_override, s->core.plan_override);
        ncp_nck_set_feed_override(s->core.ctl, pct / 100.0);
        return 0;
    case 1:
        if (pct > 100)
            return refuse(why, len, "rapid override is 0..100 %%: rapids already run at the "
                          "axes' maximum velocity");
        atomic_store(&s->core.ctl->rapid_permille, (int)lround(pct * 10));
        s->rapid_override = pct;
        return 0;
    case 2:
        if (pct > 100.0 * op->max_spindle_override + 1e-9)
            return refuse(why, len, "spindle override %g %% is above this machine's %g %% "
                          "([DISPLAY] MAX_SPINDLE_OVERRIDE = %g in its INI)", pct,
                          100.0 * op->max_spindle_override, op->max_spindle_override);
        if (pct < 100.0 * op->min_spindle_override - 1e-9)
            return refuse(why, len, "spindle override %g %% is below this machine's %g %% "
                          "([DISPLAY] MIN_SPINDLE_OVERRIDE = %g in its INI)", pct,
                          100.0 * op->min_spindle_override, op->min_spindle_override);
        s->spindle_override = pct;
        atomic_store(&s->core.ctl->spindle_permille, (int)lround(pct * 10));
        return 0;
    default:
        return refuse(why, len, "override is feed, rapid or spindle");
    }
}

static int cmd_pause(struct ncp_nck *s, char *why, size_t len)
{
    if (s->state != NCP_ST_RUNNING && s->state != NCP_ST_STEPPING && s->state != NCP_ST_MDI)
        return refuse(why, len, "nothing to pause while %s", ncp_nck_state_name(s->state));
    if (s->drop == NCK_DROP_WRITE)
        return refuse(why, len, "nothing to pause: the job has ended (what it changed is "
                      "being written to the disk)");
    s->resume_state = s->state;
    ncp_nck_feed_hold(s->core.ctl, 1);
    set_state(s, NCP_ST_PAUSED);
    return 0;
}

/* The program paused the machine (M0 M1 M60 M6): what it waits for. */
static int machine_wait(const struct ncp_nck *s)
{
    return s->machine_pause && s->core.svc->have_fb ? s->core.svc->last_fb.wait : NCK_WAIT_NONE;
}

static int cmd_resume(struct ncp_nck *s, char *why, size_t len)
{
    if (s->state == NCP_ST_PAUSED && machine_wait(s) == NCK_WAIT_TOOL)
        return refuse(why, len, "the M6 on line %u waits for the tool: cnc-ctl tool-changed "
                      "once it is in the spindle", s->core.svc->last_fb.wait_line);
    if (s->state == NCP_ST_PAUSED && s->machine_pause) {
        atomic_fetch_add(&s->core.ctl->resume_go, 1);
        s->machine_pause = 0;
    }
    if (s->state == NCP_ST_PAUSED) {
        ncp_nck_feed_hold(s->core.ctl, 0);
        set_state(s, s->resume_state);
        return 0;
    }
    if (s->state == NCP_ST_STEPPING) {
        atomic_fetch_add(&s->core.job->step_go, 1);
        return 0;
    }
    return refuse(why, len, "nothing to resume while %s", ncp_nck_state_name(s->state));
}

static int cmd_tool_changed(struct ncp_nck *s, char *why, size_t len)
{
    if (s->state != NCP_ST_PAUSED || machine_wait(s) != NCK_WAIT_TOOL)
        return refuse(why, len, "no M6 waits for a tool (%s)", ncp_nck_state_name(s->state));
    atomic_fetch_add(&s->core.ctl->tool_go, 1);
    s->machine_pause = 0;
    ncp_nck_feed_hold(s->core.ctl, 0);
    set_state(s, s->resume_state);
    return 0;
}

static int cmd_set_input(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    int i = c->ivalue[0], v = c->ivalue[1];
    if (i < 0 || i >= NCP_DIO_MAX || (v != 0 && v != 1))
        return refuse(why, len, "set-input: digital input 0..%d, value 0 or 1", NCP_DIO_MAX - 1);
    if (v)
        atomic_fetch_or(&s->core.ctl->din, 1ull << i);
    else
        atomic_fetch_and(&s->core.ctl->din, ~(1ull << i));
    return 0;
}

static int cmd_step(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (s->state == NCP_ST_ESTOP || s->state == NCP_ST_FAULT)
        return refuse(why, len, "not while %s", ncp_nck_state_name(s->state));
    int on = c->ivalue[0] != 0;
    atomic_store(&s->core.job->step, on);
    if (on && s->state == NCP_ST_RUNNING)
        set_state(s, NCP_ST_STEPPING);
    else if (!on && s->state == NCP_ST_STEPPING) {
        atomic_fetch_add(&s->core.job->step_go, 1);
        set_state(s, NCP_ST_RUNNING);
    }
    if (s->state == NCP_ST_PAUSED && s->resume_state != NCP_ST_MDI)
        s->resume_state = on ? NCP_ST_STEPPING : NCP_ST_RUNNING;
    return 0;
}

static int cmd_stop(struct ncp_nck *s, int full, char *why, size_t len)
{
    if (s->drop == NCK_DROP_WRITE)
        return 0;   /* the job has ended: nothing moves, idle once written */
    if (!moving_state(s->state))
        return s->state == NCP_ST_IDLE || s->state == NCP_ST_STOPPING
                   ? 0
                   : refuse(why, len, "not while %s", ncp_nck_state_name(s->state));
    int interp = s->core.job->kind == NCK_JOB_PROGRAM || s->core.job->kind == NCK_JOB_MDI;
    begin_drop(s, 1, full, NCP_ST_IDLE, interp);
    return 0;
}

static int cmd_estop(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    atomic_store(&n->cross.frozen, 1);
    if (s->state == NCP_ST_ESTOP)
        return 0;
    int interp = n->job->kind == NCK_JOB_PROGRAM || n->job->kind == NCK_JOB_MDI;
    if (s->drop != NCK_DROP_NONE && s->drop != NCK_DROP_HOLD) {
        s->drop_after = NCP_ST_ESTOP;   /* already dropping: end there */
        s->drop_reset |= interp;
        s->reset_after_drop = 0;
    } else {
        begin_drop(s, 0, 0, NCP_ST_ESTOP, interp);
    }
    /* The setpoints froze above: that is the E-stop the operator must see at
     * once, while the job and the planner's queue are dropped behind it. */
    set_state(s, NCP_ST_ESTOP);
    nck_post(n, NCP_EV_FAULT, NULL, 0, 0, "E-stop: setpoints frozen, drives off");
    return 0;
}

/* Where a file the operator reads lives (cnc-ctl history, tool list): its
 * path in the ACK's reason, in any state (reading it moves nothing). */
static int cmd_files(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    const char *path = !strcmp(c->text, "history")      ? s->hist.path
                       : !strcmp(c->text, "tool_table") ? s->persist.tool_path
                                                        : NULL;
    if (strcmp(c->text, "history") != 0 && strcmp(c->text, "tool_table") != 0)
        return refuse(why, len, "files: history or tool_table, not '%s'", c->text);
    if (!path || !path[0])
        return refuse(why, len, "%s", !strcmp(c->text, "history")
                                         ? "the NCK keeps no job history (its INI has no "
                                           "[DISPLAY] HISTORY_FILE)"
                                         : "the NCK has no tool table ([EMCIO] TOOL_TABLE or "
                                           "--tool-table)");
    snprintf(why, len, "%s", path);
    return 0;
}

/* Out of E-stop or a fault: the commanded position becomes the actual one
 * (the axes coasted meanwhile), the drives come on again. */
static int cmd_reset(struct ncp_nck *s, char *why, size_t len)
{
    struct nck_core *n = &s->core;
    if (s->state != NCP_ST_ESTOP && s->state != NCP_ST_FAULT && s->state != NCP_ST_IDLE)
        return refuse(why, len, "nothing to reset while %s", ncp_nck_state_name(s->state));
    /* the operator has read the errors: the NCK's, and each LLC's that is
     * back (one still stopped or gone keeps its own) */
    s->error[0] = 0;
    nck_llcs_ack(s);
    s->changed = 1;
    if (s->state == NCP_ST_IDLE)
        return 0;
    atomic_store(&n->cross.loop_fault, NCK_LF_NONE);
    if (s->drop != NCK_DROP_NONE) {
        /* the E-stop's drop is still under way: the reset's follows it */
        s->reset_after_drop = 1;
        set_state(s, NCP_ST_STOPPING);
        return 0;
    }
    /* rest at the actual position while still frozen, then let go */
    begin_drop(s, 0, 0, NCP_ST_IDLE, 0);
    return 0;
}

int ncp_nck_command(struct ncp_nck *s, const struct ncp_nck_cmd *c, char *why, size_t len)
{
    if (len)
        why[0] = 0;
    if (memchr(c->text, 0, sizeof c->text) == NULL)
        return refuse(why, len, "command text not terminated");
    int rc;
    /* whatever stops the machine ends a load's check too */
    switch (c->kind) {
    case NCP_CMD_STOP: end_check(s, NCK_CHECK_BY_STOP); break;
    case NCP_CMD_ABORT: end_check(s, NCK_CHECK_BY_ABORT); break;
    case NCP_CMD_ESTOP: end_check(s, NCK_CHECK_BY_ESTOP); break;
    case NCP_CMD_RESET: end_check(s, NCK_CHECK_BY_RESET); break;
    default: break;
    }
    if (s->loading && atomic_load(&s->load_cancel) != NCK_CHECK_RUNS &&
        waits_for_load(c->kind))
        finish_ended_check(s);
    int locked = s->state == NCP_ST_ESTOP || s->state == NCP_ST_FAULT ||
                 s->state == NCP_ST_STOPPING;
    switch (c->kind) {
    case NCP_CMD_ESTOP: rc = cmd_estop(s); break;
    case NCP_CMD_RESET:
        rc = s->state == NCP_ST_STOPPING ? refuse(why, len, "a stop is in progress")
                                         : cmd_reset(s, why, len);
        break;
    case NCP_CMD_SHUTDOWN: ncp_nck_request_shutdown(s); rc = 0; break;
    case NCP_CMD_OVERRIDE: rc = cmd_override(s, c, why, len); break;
    case NCP_CMD_STEP: rc = cmd_step(s, c, why, len); break;
    case NCP_CMD_OPTIONAL_STOP:
        atomic_store(&s->core.ctl->optional_stop, c->ivalue[0] != 0);
        rc = 0;
        break;
    case NCP_CMD_SET_INPUT: rc = cmd_set_input(s, c, why, len); break;
    case NCP_CMD_FILES:
        if ((rc = disk_wait(s, c, why, len)) == 0)
            rc = cmd_files(s, c, why, len);
        break;
    case NCP_CMD_KEEPALIVE:
        s->jog_last_ns = ncp_mono_ns();
        rc = 0;
        break;
    default:
        if (locked) {
            rc = refuse(why, len, "the NCK is %s%s", ncp_nck_state_name(s->state),
                        s->state == NCP_ST_STOPPING ? "" : " (cnc-ctl reset first)");
            break;
        }
        if (s->loading && waits_for_load(c->kind)) {
            rc = refuse(why, len, "%s is being checked: wait for its load's answer (a stop "
                        "ends the check)", s->load_path);
            break;
        }
        if ((rc = disk_wait(s, c, why, len)) != 0)
            break;
        switch (c->kind) {
        case NCP_CMD_LOAD: rc = cmd_load(s, c, why, len); break;
        case NCP_CMD_RUN: rc = cmd_run(s, c, why, len); break;
        case NCP_CMD_PAUSE: rc = cmd_pause(s, why, len); break;
        case NCP_CMD_RESUME: rc = cmd_resume(s, why, len); break;
        case NCP_CMD_TOOL_CHANGED: rc = cmd_tool_changed(s, why, len); break;
        case NCP_CMD_STOP: rc = cmd_stop(s, 0, why, len); break;
        case NCP_CMD_ABORT: rc = cmd_stop(s, 1, why, len); break;
        case NCP_CMD_MDI: rc = cmd_mdi(s, c, why, len); break;
        case NCP_CMD_JOG: rc = cmd_jog(s, c, why, len); break;
        case NCP_CMD_JOG_STOP:
            rc = s->state == NCP_ST_JOGGING ? (begin_drop(s, 1, 0, NCP_ST_IDLE, 0), 0)
                 : s->state == NCP_ST_IDLE  ? 0
                                            : refuse(why, len, "not jogging (%s)",
                                                     ncp_nck_state_name(s->state));
            break;
        case NCP_CMD_HOME: rc = cmd_home(s, c, why, len); break;
        default: rc = refuse(why, len, "unknown command %d", c->kind); break;
        }
    }
    if (rc < 0)
        s->rejected++;
    return rc;
}

/* ---- moving on ---------------------------------------------------------------------------- */

static void job_ended(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    struct nck_job *j = n->job;
    nck_job_join(n);
    int kind = j->kind;
    j->kind = NCK_JOB_NONE;
    const struct ncp_diag *d = j->map_failed ? &j->map_diag : j->rc != NCP_OK ? &j->diag : NULL;
    if (d) {
        const char *file = d->file ? d->file : kind == NCK_JOB_MDI ? "MDI" : s->program;
        snprintf(s->error, sizeof s->error, "%s:%u:%u: %s", file, d->line,
                 d->col ? d->col : 1u, d->msg);
        nck_post(n, NCP_EV_ERROR, file, d->line, d->col, "%s", d->msg);
        /* the machine stands at the end of the last good block; a program
         * ends as at M2, a mistyped MDI line leaves the modal state as it was */
        if (kind == NCK_JOB_PROGRAM)
            reset_interp(s);
        else
            sync_interp(s);
    }
    if (kind == NCK_JOB_PROGRAM) {
        int64_t end = atomic_load_explicit(&n->cross.end_ns, memory_order_relaxed);
        s->program_time = end > s->run_t0_ns ? (double)(end - s->run_t0_ns) * 1e-9 : 0;
        history_end(s, d ? "error" : "done", s->program_time);
    }
    if (kind == NCK_JOB_PROGRAM && !d) {
        char est[64] = "";
        if (s->est.state == NCP_EST_DONE)
            snprintf(est, sizeof est, " (estimate %.3f s)", s->est.program_time);
        nck_post(n, NCP_EV_INFO, s->program, 0, 0, "program finished: program time %.3f s%s",
                 s->program_time, est);
    }
    persist(s);
    /* the whole job in the trace once it is over, not at the next 64 KiB */
    if (n->setup.trace)
        nck_trace_flush(&n->svc->sum, n->setup.trace);
    if (!disk_busy(s)) {
        set_state(s, NCP_ST_IDLE);
        return;
    }
    /* the job's state until its changes are on the disk, as a drop's end */
    s->drop = NCK_DROP_WRITE;
    s->drop_after = NCP_ST_IDLE;
    s->drop_reset = 0;
    s->reset_after_drop = 0;
}

/* The loop is done homing: the axes it homed are homed, and the map and
 * the interpreter start from where it left them (a stop or E-stop during
 * it has its own drop, which ends in the state it asked for). */
static void homing_ended(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    char report[1024];
    int rc = nck_home_report(n, report, sizeof report);
    for (int a = 0; a < NCP_AXES; a++)
        if (rc == 0 && (s->homing_axes & (1 << a)))
            s->homed[a] = 1;
    s->homing_axes = 0;
    for (char *line = report, *next; line && *line; line = next) {
        next = strchr(line, '\n');
        if (next)
            *next++ = 0;
        nck_post(n, rc ? NCP_EV_ERROR : NCP_EV_INFO, NULL, 0, 0, "%s", line);
    }
    /* a fault that ended the homing (a drive's) keeps its own message as
     * the error: the homing's report is its consequence, said as an EVENT */
    int faulted = s->state == NCP_ST_FAULT ||
                  (s->drop != NCK_DROP_NONE && s->drop_after == NCP_ST_FAULT);
    if (rc && !faulted)
        snprintf(s->error, sizeof s->error, "%s", report);
    else if (!rc)
        nck_post(n, NCP_EV_INFO, NULL, 0, 0, "homed");
    if (s->state != NCP_ST_HOMING)
        return;
    memcpy(n->job->map.pos, n->cross.home.final, sizeof n->job->map.pos);
    sync_interp(s);
    if (n->setup.trace)
        nck_trace_flush(&n->svc->sum, n->setup.trace);
    /* LLCs that make their own setpoints played homing on the loop's own;
     * their stream starts again where it left the axes, as the planner's
     * does after an abort (lcm_ai.c numbers a new job; at block-level
     * points the abort's void, which carries homing's offset, lcm.c) */
    if (lcm_restarts_after_home(n->cfg))
        begin_drop(s, 0, 0, NCP_ST_IDLE, 0);
    else
        set_state(s, NCP_ST_IDLE);
}

static void check_fault(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    int f = atomic_load_explicit(&n->cross.loop_fault, memory_order_acquire);
    if (f == NCK_LF_NONE || s->state == NCP_ST_FAULT ||
        (s->drop != NCK_DROP_NONE && s->drop_after == NCP_ST_FAULT))
        return;
    if (f == NCK_LF_FERROR)
        snprintf(s->error, sizeof s->error,
                 "following error on %c: %.4f mm exceeds FERROR %.4f mm (line %u); drives off",
                 NCP_AXIS_LETTERS[n->cross.fault_axis], n->cross.fault_err, n->cfg->axis[n->cross.fault_axis].ferror,
                 n->cross.fault_line);
    else if (f == NCK_LF_TIMING)
        nck_inject_describe(n, s->error, sizeof s->error);
    else if (f == NCK_LF_JOINT)
        snprintf(s->error, sizeof s->error,
                 "joint limit: the %c joint was commanded to %.4f, beyond [%.4f, %.4f] (line %u); "
                 "drives off", NCP_AXIS_LETTERS[n->cross.fault_axis], n->cross.fault_err,
                 n->cfg->joint[n->cross.fault_axis].min_limit, n->cfg->joint[n->cross.fault_axis].max_limit,
                 n->cross.fault_line);
    else {
        char why[NCP_DIAG_MSG_MAX];
        n->cross.be.ops->describe_fault(&n->cross.be, why, sizeof why);
        snprintf(s->error, sizeof s->error, "drive fault: %s", why);
    }
    nck_post(n, NCP_EV_FAULT, NULL, n->cross.fault_line, 0, "%s", s->error);
    int interp = n->job->kind == NCK_JOB_PROGRAM || n->job->kind == NCK_JOB_MDI;
    begin_drop(s, 0, 0, NCP_ST_FAULT, interp);
}

int ncp_nck_poll(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    nck_read_cycles(n);
    check_fault(s);
    nck_llcs_poll(s);
    if (s->drop != NCK_DROP_NONE)
        drop_step(s);
    int st = s->state;
    if ((st == NCP_ST_RUNNING || st == NCP_ST_STEPPING || st == NCP_ST_MDI ||
         st == NCP_ST_JOGGING) && s->drop == NCK_DROP_NONE &&
        atomic_load(&n->job->finished) && nck_motion_done(n))
        job_ended(s);
    if (s->homing_axes && nck_home_finished(n))
        homing_ended(s);
    if (nck_estimate_poll(&s->est)) {
        estimate_ended(s);
        s->changed = 1;   /* a status now: the panel shows it at once */
    }
    /* the program paused the machine: PAUSED until resume (tool-changed) */
    if (n->svc->have_fb && n->svc->last_fb.waits != s->waits_seen) {
        st = s->state;
        if (nck_wait_operator(n->svc->last_fb.wait) && s->drop == NCK_DROP_NONE &&
            (st == NCP_ST_RUNNING || st == NCP_ST_STEPPING || st == NCP_ST_MDI)) {
            s->resume_state = st;
            s->machine_pause = 1;
            set_state(s, NCP_ST_PAUSED);
        }
        s->waits_seen = n->svc->last_fb.waits;
    }
    if (s->state == NCP_ST_JOGGING && s->jog_continuous && s->drop == NCK_DROP_NONE) {
        double limit = n->setup.jog_keepalive_s > 0 ? n->setup.jog_keepalive_s : 0.3;
        if ((double)(ncp_mono_ns() - s->jog_last_ns) * 1e-9 > limit) {
            nck_post(n, NCP_EV_INFO, NULL, 0, 0,
                     "jog stopped: no keep-alive from its client for %.1f s", limit);
            begin_drop(s, 1, 0, NCP_ST_IDLE, 0);
        }
    }
    if (n->svc->sum.trace_errno && !s->trace_said) {
        /* the service goes on (an E-stop must not wait for a disk); the
         * operator learns that what follows is not recorded */
        s->trace_said = 1;
        nck_post(n, NCP_EV_ERROR, NULL, 0, 0, "the trace ended early at t %.3f s: %s (its rows "
                 "so far are whole)", n->svc->sum.t, strerror(n->svc->sum.trace_errno));
    }
    if (s->shutdown_pending)
        end_check(s, NCK_CHECK_BY_SHUTDOWN);   /* answered by ncp_nck_pending */
    /* the writer caught up too: what it writes is said as events before
     * the service ends */
    if (s->shutdown_pending && s->drop == NCK_DROP_NONE && !moving_state(s->state) &&
        !s->loading && !s->ended_answer && !s->deferred && !disk_busy(s))
        s->shutdown = 1;
    int changed = s->changed;
    s->changed = 0;
    return changed;
}

/* ---- life ---------------------------------------------------------------------------------- */

struct ncp_nck *ncp_nck_new(const struct ncp_nck_setup *setup, struct ncp_diag *d)
{
    struct ncp_nck *s = calloc(1, sizeof *s);
    if (!s || nck_core_alloc(&s->core)) {
        free(s);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
        return NULL;
    }
    struct nck_core *n = &s->core;
    /* planned at the highest override the operator may choose and slowed
     * in time below it (loop.c), so none can take an axis past its limits */
    n->plan_override = setup->cfg->op.max_feed_override >= 1.0 ? setup->cfg->op.max_feed_override
                                                               : 1.0;
    n->cross.post_prints = 1;
    s->rapid_override = 100;
    s->spindle_override = 100;
    s->hist.path = setup->cfg->op.history_file;
    s->acfg = setup->interp;
    s->acfg.resident = 1;
    s->acfg.m66_on_machine = 1;   /* M66 waits on the machine's inputs */
    s->acfg.instance = NULL;
    /* an abort ends a long loop of the job's interpreter at once: the
     * control thread waits for that job before it answers anything else */
    s->acfg.cancel = job_abort_asked;
    s->acfg.cancel_ctx = n;
    s->interp = ncp_analyzer_new(&s->acfg, d);
    s->acfg.instance = s->interp;
    if (s->interp && (nck_persist_init(&s->persist, setup->vars, setup->cfg->op.parameter_file,
                                       s->acfg.tool_table_path, s->interp, d) ||
                      nck_writer_start(&s->writer, n, s->hist.path, &s->persist, d))) {
        ncp_nck_free(s);
        return NULL;
    }
    if (s->interp)   /* no run yet: the codes the first one starts in */
        ncp_analyzer_active_codes(s->interp, &n->cross.io.active);
    n->svc->sum.joints = ncp_kins_active(setup->cfg);
    if (setup->trace)
        nck_trace_header(setup->trace, setup->cfg, n->svc->sum.joints,
                         setup->trace_rings || setup->cfg->sched.trace_rings);
    int started = s->interp && nck_start(n, setup, 0, d) == 0;
    if (started)   /* the service starts at 100 %, whatever the plan is made for */
        ncp_nck_set_feed_override(n->ctl, 1.0);
    if (!started || nck_start_loop(n, d)) {
        ncp_nck_free(s);
        return NULL;
    }
    for (int j = 0; j < NCP_AXES; j++)
        s->homed[j] = 0;
    s->state = NCP_ST_IDLE;
    char restore[64];
    nck_persist_restore_text(&s->persist, restore, sizeof restore);
    run_state_text(s, restore, "parameter file");
    sync_interp(s);
    return s;
}

void ncp_nck_free(struct ncp_nck *s)
{
    if (!s)
        return;
    struct nck_core *n = &s->core;
    if (s->loading) {
        end_check(s, NCK_CHECK_BY_FREE);
        pthread_join(s->load_th, NULL);
        ncp_source_close(&s->load_src);
        s->loading = 0;
    }
    nck_estimate_free(&s->est);
    nck_finish(n);
    nck_read_cycles(n);
    if (n->setup.trace)
        nck_trace_flush(&n->svc->sum, n->setup.trace);
    /* at shutdown what the last job changed is written already, but for a
     * write that failed (tried again here) or a service that ended early */
    int changed = s->interp && s->writer.started
                      ? nck_persist_changes(&s->persist, s->interp, nck_writer_again(&s->writer))
                      : 0;
    nck_writer_stop(&s->writer, changed);
    nck_persist_free(&s->persist);
    nck_release(n);
    ncp_analyzer_free(s->interp);
    if (s->have_prog)
        ncp_source_close(&s->prog);
    nck_core_free(n);
    free(s);
}

void ncp_nck_request_shutdown(struct ncp_nck *s)
{
    s->shutdown_pending = 1;
    /* a job that has ended and is being written is not stopped (nor reset) */
    if (moving_state(s->state) && s->drop != NCK_DROP_WRITE)
        begin_drop(s, 1, 0, NCP_ST_IDLE, 1);
}

int ncp_nck_shutdown_requested(const struct ncp_nck *s)
{
    return s->shutdown;
}

/* ---- status ------------------------------------------------------------------------------- */

void ncp_nck_get_status(const struct ncp_nck *s, struct ncp_nck_snapshot *st)
{
    const struct nck_core *n = &s->core;
    memset(st, 0, sizeof *st);
    st->state = s->state;
    snprintf(st->program, sizeof st->program, "%s", s->program);
    /* the machine's axes only, in their order */
    st->n_axes = 0;
    for (int j = 0; j < NCP_AXES && st->n_axes < NCP_NCK_AXES_MAX; j++) {
        if (!(n->cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        int k = st->n_axes++;
        st->axes[k] = NCP_AXIS_LETTERS[j];
        st->homed[k] = s->homed[j];
        st->pos_cmd[k] = n->svc->have_fb ? n->svc->last_fb.cmd[j] : n->start[j];
        st->pos_act[k] = n->svc->have_fb ? n->svc->last_fb.act[j] : n->start[j];
    }
    st->vel = n->svc->have_fb ? n->svc->last_fb.v * 60.0 : 0;
    st->feed_override = atomic_load(&n->ctl->override_permille) / 10.0;
    st->rapid_override = s->rapid_override;
    st->spindle_override = s->spindle_override;
    pthread_mutex_t *lock = (pthread_mutex_t *)&n->cross.ev_lock;
    pthread_mutex_lock(lock);
    st->line = moving_state(s->state) && n->svc->have_fb && n->svc->last_fb.line ? n->svc->last_fb.line
                                                                       : n->cross.io.interp_line;
    /* the machine as it is (the interpreter runs ahead of it) */
    const struct nck_fb *fb = &n->svc->last_fb;
    st->spindle_speed = n->svc->have_fb ? fabs(fb->rpm) : 0;
    st->spindle_dir = fb->rpm > 0 ? 1 : fb->rpm < 0 ? -1 : 0;
    st->mist = fb->mist;
    st->flood = fb->flood;
    st->tool = fb->tool;
    st->g5x_index = n->cross.io.g5x_index ? n->cross.io.g5x_index : 1;
    st->active = n->cross.io.active;
    for (int k = 0; k < 6 && k < NCP_NCK_AXES_MAX; k++)
        st->g5x_offset[k] = n->cross.io.g5x[k];
    pthread_mutex_unlock(lock);
    st->step_mode = atomic_load(&n->job->step);
    snprintf(st->error, sizeof st->error, "%s", s->error);
    st->rejected = s->rejected;
    st->cycles = n->svc->sum.rows;
    st->deadline_misses = atomic_load(&n->cross.pub_misses);
    st->latency_max_us = (double)atomic_load(&n->cross.pub_lat_max_ns) / 1e3;
    st->estimate_state = s->est.state;
    st->estimate_s = s->est.program_time;
    st->estimate_path_mm = s->est.path_length;
    st->estimate_ferr_mm = s->est.ferr_max;
    st->estimate_compute_s = s->est.seconds;
    st->estimate_pauses = s->est.pauses;
    for (int j = 0; j < NCP_AXES; j++) {
        st->estimate_min[j] = s->est.state == NCP_EST_DONE ? s->est.ext_min[j] : 1;
        st->estimate_max[j] = s->est.state == NCP_EST_DONE ? s->est.ext_max[j] : 0;
    }
    st->program_time_s = s->program_time;
    /* the stream's time read so far is the estimate's time done (both at
     * 100 %); what is left goes at the feed override now (rapids at theirs:
     * an approximation where they differ) */
    double ovr = st->feed_override / 100.0;
    int in_run = n->job->kind == NCK_JOB_PROGRAM &&
                 (s->state == NCP_ST_RUNNING || s->state == NCP_ST_STEPPING ||
                  s->state == NCP_ST_PAUSED);
    st->remaining_s = in_run && s->est.state == NCP_EST_DONE && !s->run_from_line
                          ? fmax(0.0, s->est.program_time - n->svc->sum.job_done_s) /
                                fmax(ovr, 0.01)
                          : -1;
    if (n->cross.be.ops && n->cross.be.ops->drives) {
        struct ncp_drive_info d[NCP_NCK_AXES_MAX];
        st->n_drives = n->cross.be.ops->drives(&n->cross.be, d, NCP_NCK_AXES_MAX);
        for (int k = 0; k < st->n_drives; k++) {
            st->drive_axis[k] = NCP_AXIS_LETTERS[d[k].axis];
            st->drive_node[k] = d[k].node;
            st->drive_statusword[k] = d[k].statusword;
            st->drive_error[k] = d[k].error;
        }
    }
    if (n->cross.be.ops && n->cross.be.ops->llcs) {
        struct ncp_llc_info l[NCP_NCK_AXES_MAX];
        st->n_llcs = n->cross.be.ops->llcs(&n->cross.be, l, NCP_NCK_AXES_MAX);
        st->llc_dp = n->cfg->lcm.dp;
        for (int k = 0; k < st->n_llcs; k++) {
            st->llc_axis[k] = NCP_AXIS_LETTERS[l[k].axis];
            st->llc_state[k] = l[k].state;
            st->llc_clock_offset_ns[k] = l[k].clock_offset_ns;
            st->llc_ferr_nm[k] = l[k].ferr_nm;
            st->llc_error[k] = l[k].error;
        }
    }
}

