/* Job threads: the producers of the segment ring. A program or an MDI line
 * goes through the interpreter and the canon map; a jog or a homing move is a
 * list of lines made here. One job at a time; its thread ends with an END
 * message, after which the planner runs the rest to a stop. */
#include "nck_int.h"

#include "ncpar/executor.h"

#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static void nap_us(long us)
{
    struct timespec ts = { 0, us * 1000 };
    nanosleep(&ts, NULL);
}

static int push_wait(struct nck *n, const struct nck_seg_msg *m)
{
    while (ncp_spsc_push(&n->segs, m) != 0) {
        if (atomic_load(&n->job.abort))
            return -1;
        nap_us(100);
    }
    return 0;
}

/* END or SYNC: the planner brings what it has to a stop. marks_sent already
 * counts the stretch this message closes; after a SYNC the next one opens. */
static int push_mark(struct nck *n, int kind)
{
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    m.kind = kind;
    if (push_wait(n, &m))
        return -1;
    n->job.marks++;
    if (kind == NCK_MSG_SYNC)
        atomic_fetch_add_explicit(&n->marks_sent, 1, memory_order_release);
    return 0;
}

static int push_seg(struct nck *n, const struct ncp_seg *s)
{
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    m.kind = NCK_MSG_SEG;
    m.seg = *s;
    n->job.seen_motion = 1;
    return push_wait(n, &m);
}

void nck_line(const struct nck *n, struct ncp_seg *s, const double from[NCP_AXES],
              const double to[NCP_AXES], double feed, int traverse)
{
    memset(s, 0, sizeof *s);
    s->kind = NCP_SEG_LINE;
    s->term = NCP_TERM_STOP;
    s->traverse = (uint8_t)traverse;
    s->line = n->job.step_line;
    memcpy(s->start, from, sizeof s->start);
    memcpy(s->end, to, sizeof s->end);
    double l2 = 0;
    for (int j = 0; j < NCP_AXES; j++)
        l2 += (to[j] - from[j]) * (to[j] - from[j]);
    s->length = sqrt(l2);
    s->feed = traverse ? n->cfg->max_linear_vel : feed;
}

/* ---- single block ------------------------------------------------------------- */

/* The job's motion so far has run to its end. */
static int reached(const struct nck *n, uint64_t base)
{
    return atomic_load_explicit(&n->ends_taken, memory_order_acquire) >= base + n->job.marks;
}

/* After a block that moved: stop at its end and wait for resume. */
static int block_stop(struct nck *n)
{
    struct nck_job *j = &n->job;
    if (push_mark(n, NCK_MSG_SYNC))
        return -1;
    uint64_t base = n->marks_base;
    atomic_store(&j->waiting, 1);
    while (!atomic_load(&j->abort) &&
           (!reached(n, base) || atomic_load(&j->step_go) <= j->step_used))
        nap_us(1000);
    atomic_store(&j->waiting, 0);
    j->step_used = atomic_load(&j->step_go);
    return atomic_load(&j->abort) ? -1 : 0;
}

/* ---- run from line: skip, then approach safely --------------------------------- */

/* Z up to the highest Z the skipped part reached (or where Z is, if higher),
 * then X Y, then Z down: the way a machinist brings a tool back into a part. */
static int approach(struct nck *n, uint32_t line)
{
    struct nck_job *j = &n->job;
    double at[NCP_AXES], up[NCP_AXES], over[NCP_AXES];
    memcpy(at, j->origin, sizeof at);
    memcpy(up, at, sizeof up);
    up[2] = fmax(j->max_z, at[2]);
    memcpy(over, n->map.pos, sizeof over);
    over[2] = up[2];
    const double *pts[] = { at, up, over, n->map.pos };
    j->step_line = line;
    for (int k = 0; k < 3; k++) {
        struct ncp_seg s;
        nck_line(n, &s, pts[k], pts[k + 1], 0, 1);
        if (s.length > 1e-9 && push_seg(n, &s))
            return -1;
    }
    nck_post(n, NCP_EV_INFO, NULL, line, 0,
             "run from line %u: lines before it interpreted without motion; approached "
             "X%.3f Y%.3f Z%.3f by Z%.3f", line, n->map.pos[0], n->map.pos[1], n->map.pos[2],
             up[2]);
    return 0;
}

/* ---- interpreter jobs ------------------------------------------------------------ */

void nck_note_state(struct nck *n, const struct ncp_canon *op)
{
    /* most calls are motion: leave those without taking the lock */
    switch (op->kind) {
    case NCP_C_SET_SPINDLE_SPEED: case NCP_C_START_SPINDLE_CLOCKWISE:
    case NCP_C_START_SPINDLE_COUNTERCLOCKWISE: case NCP_C_STOP_SPINDLE_TURNING:
    case NCP_C_MIST_ON: case NCP_C_MIST_OFF: case NCP_C_FLOOD_ON: case NCP_C_FLOOD_OFF:
    case NCP_C_CHANGE_TOOL: case NCP_C_CHANGE_TOOL_NUMBER: case NCP_C_SET_G5X_OFFSET:
        break;
    default:
        return;
    }
    struct nck_io *io = &n->io;
    pthread_mutex_lock(&n->ev_lock);
    switch (op->kind) {
    case NCP_C_SET_SPINDLE_SPEED: io->speed = op->spindle_speed.speed; break;
    case NCP_C_START_SPINDLE_CLOCKWISE: io->dir = 1; break;
    case NCP_C_START_SPINDLE_COUNTERCLOCKWISE: io->dir = -1; break;
    case NCP_C_STOP_SPINDLE_TURNING: io->dir = 0; break;
    case NCP_C_MIST_ON: io->mist = 1; break;
    case NCP_C_MIST_OFF: io->mist = 0; break;
    case NCP_C_FLOOD_ON: io->flood = 1; break;
    case NCP_C_FLOOD_OFF: io->flood = 0; break;
    case NCP_C_CHANGE_TOOL:
    case NCP_C_CHANGE_TOOL_NUMBER: io->tool = op->tool.tool; break;
    case NCP_C_SET_G5X_OFFSET:
        io->g5x_index = op->offset.index;
        for (int k = 0; k < 6; k++)
            io->g5x[k] = op->offset.v[k];
        break;
    default: break;
    }
    pthread_mutex_unlock(&n->ev_lock);
}

static void post_text(struct nck *n, const struct ncp_cmd *cmd, const struct ncp_canon *op,
                      int kind)
{
    size_t off = op->text_off, len = op->text_len;
    if (off > NCP_CMD_TEXT_POOL || len > NCP_CMD_TEXT_POOL - off)
        return;
    while (len && (cmd->text[off + len - 1] == '\n'))
        len--;
    nck_post(n, kind, NULL, cmd->line, 0, "%.*s", (int)len, cmd->text + off);
}

/* A segment of a run from line N: before N it only moves the map along. */
static int take_seg(struct nck *n, const struct ncp_seg *s)
{
    struct nck_job *j = &n->job;
    if (j->from_line && !j->reached) {
        j->max_z = fmax(j->max_z, fmax(s->start[2], s->end[2]));
        return 0;
    }
    return push_seg(n, s);
}

static int emit_segments(void *ctx, const struct ncp_cmd *cmd)
{
    struct nck *n = ctx;
    struct nck_job *j = &n->job;
    if (atomic_load(&j->abort))
        return 1;
    if (cmd->text_used && !n->post_prints)
        (void)ncp_exec_write_prints(cmd, stderr);
    if (j->from_line && !j->reached && cmd->line >= j->from_line) {
        /* the map's position is where the skipped part left the tool */
        double target[NCP_AXES];
        memcpy(target, n->map.pos, sizeof target);
        j->reached = 1;
        if (approach(n, cmd->line))
            return 1;
        memcpy(n->map.pos, target, sizeof n->map.pos);
    }
    int seen = j->seen_motion;
    j->seen_motion = 0;
    struct ncp_seg seg;
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        const struct ncp_canon *op = &cmd->ops[i];
        if (n->post_prints && op->kind == NCP_C_PRINT)
            post_text(n, cmd, op, NCP_EV_PRINT);
        else if (n->post_prints && op->kind == NCP_C_MESSAGE)
            post_text(n, cmd, op, NCP_EV_MSG);
        nck_note_state(n, op);
        int rc = ncp_canon_map_op(&n->map, op, cmd->line, &seg, &j->map_diag);
        while (rc == 1) {
            if (take_seg(n, &seg))
                return 1;
            rc = ncp_canon_map_more(&n->map, &seg, &j->map_diag);
        }
        if (rc < 0) {
            j->map_failed = 1;
            return 1;
        }
    }
    if (n->post_prints) {   /* a serving NCK's status shows it */
        pthread_mutex_lock(&n->ev_lock);
        n->io.interp_line = cmd->line;
        pthread_mutex_unlock(&n->ev_lock);
    }
    int moved = j->seen_motion;
    j->seen_motion |= seen;
    if (moved && atomic_load(&j->step) && (!j->from_line || j->reached)) {
        j->step_line = cmd->line;
        if (block_stop(n))
            return 1;
    }
    return 0;
}

static void *interp_main(void *arg)
{
    struct nck *n = arg;
    struct nck_job *j = &n->job;
    struct ncp_output out = { .ctx = n, .emit = emit_segments };
    memset(&j->diag, 0, sizeof j->diag);
    j->rc = j->interpret(j->interp_ctx, &out, &j->diag);
    push_mark(n, NCK_MSG_END);
    atomic_store(&j->finished, 1);
    return NULL;
}

static void *moves_main(void *arg)
{
    struct nck *n = arg;
    struct nck_job *j = &n->job;
    for (int k = 0; k < j->n_moves; k++)
        if (j->moves[k].length > 1e-9 && push_seg(n, &j->moves[k]))
            break;
    push_mark(n, NCK_MSG_END);
    atomic_store(&j->finished, 1);
    return NULL;
}

/* The caller filled n->job (kind, interpret or moves, from_line); the
 * planner is idle at the map's position. */
int nck_job_start(struct nck *n)
{
    struct nck_job *j = &n->job;
    atomic_store(&j->finished, 0);
    atomic_store(&j->abort, 0);
    atomic_store(&j->waiting, 0);
    j->marks = 0;
    j->map_failed = 0;
    j->rc = NCP_OK;
    j->reached = 0;
    j->seen_motion = 0;
    j->step_used = atomic_load(&j->step_go);
    j->max_z = n->map.pos[2];
    memset(&j->map_diag, 0, sizeof j->map_diag);
    memcpy(j->origin, n->map.pos, sizeof j->origin);
    n->marks_base = atomic_load(&n->marks_sent);
    /* the stretch the job's first END or SYNC closes */
    atomic_fetch_add_explicit(&n->marks_sent, 1, memory_order_release);
    void *(*fn)(void *) = j->kind == NCK_JOB_MOVE ? moves_main : interp_main;
    const struct ncp_rt_place *pl = &n->cfg->interp;
    if (ncp_rt_start(&j->thread, pl, fn, n, NULL)) {
        atomic_fetch_sub(&n->marks_sent, 1);
        j->kind = NCK_JOB_NONE;
        return -1;
    }
    j->started = 1;
    return 0;
}

void nck_job_join(struct nck *n)
{
    if (n->job.started)
        pthread_join(n->job.thread, NULL);
    n->job.started = 0;
}
