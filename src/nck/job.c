/* Job threads: the producers of the segment ring. A program or an MDI line
 * goes through the interpreter and the canon map; a jog or a homing move is a
 * list of lines made here. One job at a time; its thread ends with an END
 * message, after which the planner runs the rest to a stop. */
#include "nck_int.h"
#include "job_state.h"

#include "ncpar/executor.h"
#include "ncpar/clock.h"

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

/* Into one of the rings the loop and the planner read: waits while it is
 * full, gives up when the job is aborted. */
static int ring_push(struct nck_core *n, struct ncp_spsc *ring, const void *item)
{
    while (ncp_spsc_push(ring, item) != 0) {
        if (atomic_load(&n->job->abort))
            return -1;
        nap_us(100);
    }
    return 0;
}

/* With TRACE_RINGS the job's cycle is the time from one segment to the next. */
static int push_wait(struct nck_core *n, const struct nck_seg_msg *m)
{
    int rc = ring_push(n, &n->cross.segs, m);
    if (n->trace_rings) {
        static _Thread_local int64_t last;
        int64_t now = ncp_mono_ns();
        if (last)
            atomic_store_explicit(&n->cross.job_cycle_ns, now - last, memory_order_relaxed);
        last = now;
    }
    return rc;
}

static int take_seg(struct nck_core *n, const struct ncp_seg *s);

/* ---- machine functions ------------------------------------------------------------ */

/* The pack gathered so far goes to the position loop; one that waits for
 * motion is announced by an AUX stop, one that goes with motion rides on the
 * next segment (push_seg numbers it). */
static int sync_flush(struct nck_core *n);

/* The pack, numbered, into the loop's ring; the AUX message that makes the
 * planner stop for it (m: its other fields) when stop is set. */
static int send_pack(struct nck_core *n, int stop, struct nck_seg_msg *m)
{
    struct nck_job *j = n->job;
    j->aux.seq = ++n->job->aux_seq;
    if (ring_push(n, &n->cross.auxq, &j->aux))
        return -1;
    j->aux.n = 0;
    j->aux_stop = 0;
    if (!stop)
        return 0;
    m->kind = NCK_MSG_AUX;
    m->aux = n->job->aux_seq;
    return push_wait(n, m);
}

static int aux_flush(struct nck_core *n)
{
    struct nck_job *j = n->job;
    if (sync_flush(n))
        return -1;
    if (j->aux.n == 0)
        return 0;
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    return send_pack(n, j->aux_stop, &m);
}

static int aux_add(struct nck_core *n, int kind, int idx, int32_t i, double v, uint32_t line,
                   int stop)
{
    struct nck_job *j = n->job;
    if ((j->aux.n == NCK_AUX_PACK || j->run.n > 0) && aux_flush(n))
        return -1;
    struct nck_aux *a = &j->aux.a[j->aux.n++];
    memset(a, 0, sizeof *a);
    a->kind = (uint8_t)kind;
    a->idx = (int16_t)idx;
    a->i = i;
    a->v = v;
    a->line = line;
    j->aux_stop |= stop;
    return 0;
}

/* END or SYNC: the planner brings what it has to a stop. marks_sent already
 * counts the stretch this message closes; after a SYNC the next one opens. */
static int push_mark(struct nck_core *n, int kind)
{
    if (aux_flush(n))
        return -1;
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    m.kind = kind;
    m.aux = n->job->aux_seq;
    /* the stretch after a SYNC is open before its stop can be reached: a
     * batch run's loop ends only at a stop with no stretch open after it */
    if (kind == NCK_MSG_SYNC)
        atomic_fetch_add_explicit(&n->cross.marks_sent, 1, memory_order_release);
    if (push_wait(n, &m))
        return -1;
    n->job->marks++;
    return 0;
}

/* ---- spindle-synchronised runs ----------------------------------------------------- */

/* The run gathered so far goes to the position loop (sync ring), with the
 * action that starts it after a stop at its start; the planner goes on
 * from its end. */
static int sync_flush(struct nck_core *n)
{
    struct nck_job *j = n->job;
    if (j->run.n == 0)
        return 0;
    if (ring_push(n, &n->cross.syncq, &j->run))
        return -1;
    const struct nck_sync_run *r = &j->run;
    double end[NCP_AXES];
    memcpy(end, r->tap ? r->start : r->l[r->n - 1].end, sizeof end);
    uint32_t line = r->l[0].line;
    j->run.n = 0;
    /* what was gathered before the run happens before it */
    if (j->aux.n == NCK_AUX_PACK && aux_flush(n))
        return -1;
    struct nck_aux *a = &j->aux.a[j->aux.n++];
    memset(a, 0, sizeof *a);
    a->kind = NCK_AUX_SYNC;
    a->line = line;
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    m.jump = 1;
    memcpy(m.seg.end, end, sizeof m.seg.end);
    n->job->seen_motion = 1;
    return send_pack(n, 1, &m);
}

/* A synchronised line joins the run being gathered (a rigid tap is a run
 * of its own; its way out is the loop's). */
static int sync_add(struct nck_core *n, const struct ncp_seg *s)
{
    struct nck_job *j = n->job;
    if (s->sync == NCP_SYNC_TAP_OUT)
        return 0;
    if ((j->run.n == NCK_SYNC_LINES || j->run.tap || s->sync == NCP_SYNC_TAP) && sync_flush(n))
        return -1;
    /* the run waits for the spindle itself (at speed, then the index) */
    j->need_at_speed = 0;
    if (j->run.n == 0) {
        memcpy(j->run.start, s->start, sizeof j->run.start);
        j->run.tap = s->sync == NCP_SYNC_TAP;
    }
    struct nck_sync_line *l = &j->run.l[j->run.n++];
    memcpy(l->end, s->end, sizeof l->end);
    l->len = s->length;
    l->pitch = s->pitch;
    l->line = s->line;
    return 0;
}

static int push_seg(struct nck_core *n, const struct ncp_seg *s)
{
    struct nck_job *j = n->job;
    if (s->sync)
        return sync_add(n, s);
    /* LinuxCNC's at-speed: the first feed after a spindle start or speed
     * change starts once the spindle has reached its speed */
    if (j->need_at_speed && !s->traverse && s->kind != NCP_SEG_DWELL) {
        j->need_at_speed = 0;
        if (aux_add(n, NCK_AUX_AT_SPEED, 0, 0, 0, s->line, 1))
            return -1;
    }
    if (aux_flush(n))
        return -1;
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    m.kind = NCK_MSG_SEG;
    m.seg = *s;
    m.seg.aux = n->job->aux_seq;
    n->job->seen_motion = 1;
    return push_wait(n, &m);
}

void nck_line(const struct nck_core *n, struct ncp_seg *s, const double from[NCP_AXES],
              const double to[NCP_AXES], double feed, int traverse)
{
    memset(s, 0, sizeof *s);
    s->kind = NCP_SEG_LINE;
    s->term = NCP_TERM_STOP;
    s->traverse = (uint8_t)traverse;
    s->line = n->job->step_line;
    memcpy(s->start, from, sizeof s->start);
    memcpy(s->end, to, sizeof s->end);
    ncp_seg_set_length(s);
    s->feed = traverse ? n->cfg->max_linear_vel : feed;
    s->tool_z = n->job->map.tool[2];
}

/* ---- single block ------------------------------------------------------------- */

/* The job's motion so far has run to its end. */
static int reached(const struct nck_core *n, uint64_t base)
{
    return atomic_load_explicit(&n->cross.ends_taken, memory_order_acquire) >= base + n->job->marks;
}

/* After a block that moved: stop at its end and wait for resume. */
static int block_stop(struct nck_core *n)
{
    struct nck_job *j = n->job;
    if (push_mark(n, NCK_MSG_SYNC))
        return -1;
    uint64_t base = n->job->marks_base;
    atomic_store(&n->cross.job_waiting, 1);
    while (!atomic_load(&j->abort) &&
           (!reached(n, base) || atomic_load(&j->step_go) <= j->step_used))
        nap_us(1000);
    atomic_store(&n->cross.job_waiting, 0);
    j->step_used = atomic_load(&j->step_go);
    return atomic_load(&j->abort) ? -1 : 0;
}

/* ---- run from line: skip, then approach safely --------------------------------- */

/* Z up to the highest Z the skipped part reached (or where Z is, if higher),
 * then X Y, then Z down: the way a machinist brings a tool back into a part. */
static int approach(struct nck_core *n, uint32_t line)
{
    struct nck_job *j = n->job;
    double at[NCP_AXES], up[NCP_AXES], over[NCP_AXES];
    memcpy(at, j->origin, sizeof at);
    memcpy(up, at, sizeof up);
    up[2] = fmax(j->max_z, at[2]);
    memcpy(over, n->job->map.pos, sizeof over);
    over[2] = up[2];
    const double *pts[] = { at, up, over, n->job->map.pos };
    j->step_line = line;
    for (int k = 0; k < 3; k++) {
        struct ncp_seg s;
        nck_line(n, &s, pts[k], pts[k + 1], 0, 1);
        if (s.length > 1e-9 && push_seg(n, &s))
            return -1;
    }
    nck_post(n, NCP_EV_INFO, NULL, line, 0,
             "run from line %u: lines before it interpreted without motion; approached "
             "X%.3f Y%.3f Z%.3f by Z%.3f", line, n->job->map.pos[0], n->job->map.pos[1], n->job->map.pos[2],
             up[2]);
    return 0;
}

/* ---- interpreter jobs ------------------------------------------------------------ */

void nck_note_state(struct nck_core *n, const struct ncp_canon *op)
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
    struct nck_io *io = &n->cross.io;
    pthread_mutex_lock(&n->cross.ev_lock);
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
    case NCP_C_CHANGE_TOOL_NUMBER: io->tool = op->tool.number; break;
    case NCP_C_SET_G5X_OFFSET:
        io->g5x_index = op->offset.index;
        for (int k = 0; k < 6; k++)
            io->g5x[k] = op->offset.v[k];
        break;
    default: break;
    }
    pthread_mutex_unlock(&n->cross.ev_lock);
}

static void post_text(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op,
                      int kind)
{
    size_t off = op->text_off, len = op->text_len;
    if (off > NCP_CMD_TEXT_POOL || len > NCP_CMD_TEXT_POOL - off)
        return;
    while (len && (cmd->text[off + len - 1] == '\n'))
        len--;
    nck_post(n, kind, NULL, cmd->line, 0, "%.*s", (int)len, cmd->text + off);
}

/* M6: the spindle was stopped by the interpreter's own call before it;
 * Z to machine 0 first with TOOL_CHANGE_QUILL_UP, then to
 * TOOL_CHANGE_POSITION (Z first when that is up), then wait for the change. */
static int tool_change(struct nck_core *n, const struct ncp_canon *op, uint32_t line)
{
    const struct ncp_io_cfg *io = &n->cfg->io;
    double at[NCP_AXES], pts[3][NCP_AXES];
    int k = 0;
    memcpy(at, n->job->map.pos, sizeof at);
    if (io->quill_up) {
        memcpy(pts[k], at, sizeof at);
        pts[k++][2] = 0;
    }
    if (io->have_tc_pos) {
        const double *last = k ? pts[k - 1] : at;
        if (io->tc_pos[2] > last[2]) {
            memcpy(pts[k], last, sizeof at);
            pts[k++][2] = io->tc_pos[2];
        }
        /* the change position is X Y Z: the other axes stay where they are */
        memcpy(pts[k], k ? pts[k - 1] : at, sizeof at);
        memcpy(pts[k++], io->tc_pos, sizeof io->tc_pos);
    }
    for (int p = 0; p < k; p++) {
        struct ncp_seg s;
        nck_line(n, &s, p ? pts[p - 1] : at, pts[p], 0, 1);
        s.line = line;
        if (s.length > 1e-9 && take_seg(n, &s))
            return -1;
    }
    if (k)
        memcpy(n->job->map.pos, pts[k - 1], sizeof n->job->map.pos);
    /* the change itself with the spindle at rest (rs274 stopped it) */
    return aux_add(n, NCK_AUX_AT_SPEED, 0, 0, 0, line, 1) ||
           aux_add(n, NCK_AUX_TOOL, 0, op->tool.number, 0, line, 1);
}

/* An S above the spindle's top speed runs at the top, as LinuxCNC's
 * spindle does, and the operator is told once per such S. */
static double spindle_capped(struct nck_core *n, double s, uint32_t line)
{
    double top = n->cfg->io.spindle_max_rpm;
    if (!(top > 0) || s <= top)
        return s;
    if (s != n->job->capped_said) {
        n->job->capped_said = s;
        if (n->batch && !n->quiet)
            fprintf(stderr, "%sline %u: S%g is above the spindle's top speed ([SPINDLE_0] "
                            "MAX_RPM): it turns at %.0f rpm\n", n->label ? n->label : "", line,
                    s, top);
        else
            nck_post(n, NCP_EV_INFO, NULL, line, 0, "S%g is above the spindle's top speed "
                     "([SPINDLE_0] MAX_RPM): it turns at %.0f rpm", s, top);
    }
    return top;
}

static int spindle_cmd(struct nck_core *n, uint32_t line)
{
    double s = n->job->map.speed;
    if (n->job->map.css_max > 0 && s > n->job->map.css_max)
        s = n->job->map.css_max;
    if (n->job->map.spindle_dir != 0)
        s = spindle_capped(n, s, line);
    n->job->need_at_speed = n->job->map.spindle_dir != 0;
    return aux_add(n, NCK_AUX_SPINDLE, 0, 0, n->job->map.spindle_dir * s, line, 1);
}

/* A call that is a machine function: into the pack. M62/M63/M67 go with the
 * next motion; everything else waits for motion, as in LinuxCNC. Called
 * after the map took the call (its spindle state is the new one). */
static int take_aux(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op,
                    int after_pallet)
{
    uint32_t line = cmd->line;
    int idx = op->output.index;
    switch (op->kind) {
    case NCP_C_SET_SPINDLE_SPEED:
    case NCP_C_START_SPINDLE_CLOCKWISE:
    case NCP_C_START_SPINDLE_COUNTERCLOCKWISE:
    case NCP_C_STOP_SPINDLE_TURNING:
        return spindle_cmd(n, line);
    case NCP_C_ORIENT_SPINDLE:
        n->job->need_at_speed = 0;
        return aux_add(n, NCK_AUX_ORIENT, 0, op->orient.direction, op->orient.angle, line, 1);
    case NCP_C_FLOOD_ON: case NCP_C_FLOOD_OFF:
        return aux_add(n, NCK_AUX_FLOOD, 0, op->kind == NCP_C_FLOOD_ON, 0, line, 1);
    case NCP_C_MIST_ON: case NCP_C_MIST_OFF:
        return aux_add(n, NCK_AUX_MIST, 0, op->kind == NCP_C_MIST_ON, 0, line, 1);
    case NCP_C_SELECT_TOOL:
        return aux_add(n, NCK_AUX_PREPARE, 0, op->tool.number, 0, line, 0);
    case NCP_C_CHANGE_TOOL:
        return tool_change(n, op, line);
    case NCP_C_CHANGE_TOOL_NUMBER:  /* M61: the tool is in the spindle already */
        return aux_add(n, NCK_AUX_PREPARE, 1, op->tool.number, 0, line, 1);
    case NCP_C_ENABLE_FEED_OVERRIDE: case NCP_C_DISABLE_FEED_OVERRIDE:
        return aux_add(n, NCK_AUX_ENABLE, 0, NCK_EN_FEED_OVERRIDE,
                       op->kind == NCP_C_ENABLE_FEED_OVERRIDE, line, 1);
    case NCP_C_ENABLE_SPEED_OVERRIDE: case NCP_C_DISABLE_SPEED_OVERRIDE:
        return aux_add(n, NCK_AUX_ENABLE, 0, NCK_EN_SPEED_OVERRIDE,
                       op->kind == NCP_C_ENABLE_SPEED_OVERRIDE, line, 1);
    case NCP_C_ENABLE_FEED_HOLD: case NCP_C_DISABLE_FEED_HOLD:
        return aux_add(n, NCK_AUX_ENABLE, 0, NCK_EN_FEED_HOLD,
                       op->kind == NCP_C_ENABLE_FEED_HOLD, line, 1);
    case NCP_C_ENABLE_ADAPTIVE_FEED: case NCP_C_DISABLE_ADAPTIVE_FEED:
        return aux_add(n, NCK_AUX_ENABLE, 0, NCK_EN_ADAPTIVE,
                       op->kind == NCP_C_ENABLE_ADAPTIVE_FEED, line, 1);
    case NCP_C_PROGRAM_STOP:
        return aux_add(n, NCK_AUX_PAUSE, 0, after_pallet ? NCK_WAIT_M60 : NCK_WAIT_M0, 0, line, 1);
    case NCP_C_OPTIONAL_PROGRAM_STOP:
        return aux_add(n, NCK_AUX_PAUSE, 0, NCK_WAIT_M1, 0, line, 1);
    case NCP_C_PALLET_SHUTTLE:    /* no pallets: the PROGRAM_STOP after it pauses */
        return 0;
    case NCP_C_SET_AUX_OUTPUT_BIT: case NCP_C_CLEAR_AUX_OUTPUT_BIT:
    case NCP_C_SET_MOTION_OUTPUT_BIT: case NCP_C_CLEAR_MOTION_OUTPUT_BIT:
        return aux_add(n, NCK_AUX_DOUT, idx,
                       op->kind == NCP_C_SET_AUX_OUTPUT_BIT ||
                           op->kind == NCP_C_SET_MOTION_OUTPUT_BIT,
                       0, line,
                       op->kind == NCP_C_SET_AUX_OUTPUT_BIT ||
                           op->kind == NCP_C_CLEAR_AUX_OUTPUT_BIT);
    case NCP_C_SET_AUX_OUTPUT_VALUE: case NCP_C_SET_MOTION_OUTPUT_VALUE:
        return aux_add(n, NCK_AUX_AOUT, idx, 0, op->output.value, line,
                       op->kind == NCP_C_SET_AUX_OUTPUT_VALUE);
    case NCP_C_WAIT_INPUT: {
        int r = aux_add(n, NCK_AUX_WAIT_INPUT, op->wait_input.index, op->wait_input.mode,
                        op->wait_input.timeout, line, 1);
        if (!r)
            n->job->aux.a[n->job->aux.n - 1].a = (uint8_t)op->wait_input.analog;
        return r;
    }
    default:
        return 0;   /* RAW_TEXT's orient wait: the orient itself waits */
    }
}

/* Outputs and inputs the simulated machine has: anything else is refused. */
static int aux_range(const struct ncp_canon *op, uint32_t line, struct ncp_diag *d)
{
    int digital = op->kind == NCP_C_SET_AUX_OUTPUT_BIT || op->kind == NCP_C_CLEAR_AUX_OUTPUT_BIT ||
                  op->kind == NCP_C_SET_MOTION_OUTPUT_BIT ||
                  op->kind == NCP_C_CLEAR_MOTION_OUTPUT_BIT;
    int analog = op->kind == NCP_C_SET_AUX_OUTPUT_VALUE ||
                 op->kind == NCP_C_SET_MOTION_OUTPUT_VALUE;
    if (op->kind == NCP_C_WAIT_INPUT) {
        analog = op->wait_input.analog;
        digital = !analog;
        if ((digital && op->wait_input.index >= NCP_DIO_MAX) ||
            (analog && op->wait_input.index >= NCP_AIO_MAX))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                                "M66 %c%d: this machine has %s inputs %c0..%c%d", analog ? 'E' : 'P',
                                op->wait_input.index, analog ? "analog" : "digital",
                                analog ? 'E' : 'P', analog ? 'E' : 'P',
                                (analog ? NCP_AIO_MAX : NCP_DIO_MAX) - 1);
        return 0;
    }
    if (digital && (op->output.index < 0 || op->output.index >= NCP_DIO_MAX))
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                            "digital output P%d: this machine has P0..P%d", op->output.index,
                            NCP_DIO_MAX - 1);
    if (analog && (op->output.index < 0 || op->output.index >= NCP_AIO_MAX))
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                            "analog output E%d: this machine has E0..E%d", op->output.index,
                            NCP_AIO_MAX - 1);
    return 0;
}

int nck_check_call(const struct ncp_cmd *cmd, const struct ncp_canon *op, struct ncp_diag *d)
{
    const char *text = NULL;
    char buf[64];
    if (op->kind == NCP_C_RAW_TEXT) {
        size_t off = op->text_off, len = op->text_len;
        if (off <= NCP_CMD_TEXT_POOL && len <= NCP_CMD_TEXT_POOL - off) {
            snprintf(buf, sizeof buf, "%.*s", (int)len, cmd->text + off);
            text = buf;
        }
    }
    if (nck_call_class(op, text) == NCK_CALL_REFUSED) {
        if (op->kind == NCP_C_RAW_TEXT)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, cmd->line, 0,
                                "%s: a call this machine cannot act on", text ? text : "?");
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, cmd->line, 0, "%s", nck_call_what(op->kind));
    }
    return aux_range(op, cmd->line, d);
}

/* (LOGOPEN,...) and the rest: LinuxCNC writes them to a log file; the NCK
 * shows them to the operator instead (an event, or stderr in a batch run)
 * and writes no file on a program's say-so. */
static void log_text(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op)
{
    if (n->cross.post_prints) {
        post_text(n, cmd, op, NCP_EV_INFO);
        return;
    }
    size_t off = op->text_off, len = op->text_len;
    if (off > NCP_CMD_TEXT_POOL || len > NCP_CMD_TEXT_POOL - off)
        return;
    static const char *const what[] = { "LOGOPEN", "LOGAPPEND", "LOGCLOSE", "LOG" };
    if (!n->quiet)
        fprintf(stderr, "%sline %u: %s: %.*s\n", n->label ? n->label : "", cmd->line,
                what[op->kind - NCP_C_LOGOPEN], (int)len, cmd->text + off);
}

/* Run from line: the spindle and coolant the skipped part left on come on
 * before the approach, as on a controller that restores the modal state. */
static int restore_machine(struct nck_core *n, uint32_t line)
{
    pthread_mutex_lock(&n->cross.ev_lock);
    int mist = n->cross.io.mist, flood = n->cross.io.flood;
    pthread_mutex_unlock(&n->cross.ev_lock);
    if (aux_add(n, NCK_AUX_MIST, 0, mist, 0, line, 1) ||
        aux_add(n, NCK_AUX_FLOOD, 0, flood, 0, line, 1))
        return -1;
    return n->job->map.spindle_dir ? spindle_cmd(n, line) : 0;
}

/* A segment of a run from line N: before N it only moves the map along. */
static int take_seg(struct nck_core *n, const struct ncp_seg *s)
{
    struct nck_job *j = n->job;
    if (j->from_line && !j->reached) {
        j->max_z = fmax(j->max_z, fmax(s->start[2], s->end[2]));
        return 0;
    }
    return push_seg(n, s);
}

/* ---- queue busters ----------------------------------------------------------------- */

/* A probe move, an M66 or an M6 was sent: run the motion so far to a stop, wait
 * until the machine is there, and answer the interpreter with what the
 * machine found. The interpreter makes no command after the buster until
 * it has the answer, so this thread waits for nothing it has yet to send. */
/* The motion sent so far runs to a stop and the machine stands there: -1
 * when the job is aborted meanwhile. */
static int drain(struct nck_core *n)
{
    struct nck_job *j = n->job;
    if (push_mark(n, NCK_MSG_SYNC))
        return -1;
    uint64_t base = n->job->marks_base;
    while (!reached(n, base)) {
        if (atomic_load(&j->abort))
            return -1;
        nap_us(200);
    }
    return 0;
}

static int buster(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op)
{
    struct nck_job *j = n->job;
    if (drain(n))
        return -1;
    struct ncp_machine_sync *ms = &j->answer;
    if (op->kind == NCP_C_CHANGE_TOOL) {
        /* where the change left the axes (the change position, or where
         * they were): the next block's position and #5420.. */
        ncp_canon_map_to_program(&n->job->map, n->job->map.pos, ms->pos);
        ms->what |= NCP_SYNC_POSITION;
        return 0;
    }
    if (op->kind == NCP_C_WAIT_INPUT) {
        ms->what |= NCP_SYNC_INPUT;
        ms->input = n->cross.m66_result;
        return 0;
    }
    const struct nck_probe_result *p = &n->cross.probe;
    if (p->error != NCK_PROBE_OK) {
        ncp_diag_set(&j->map_diag, NCP_ERR_SEMANTIC, cmd->line, 0, "%s",
                     p->error == NCK_PROBE_TRIPPED_AT_START
                         ? "Probe is already tripped when starting G38.2 or G38.3 move"
                         : "Probe is not tripped when starting G38.4 or G38.5 move");
        return -1;
    }
    if (!p->tripped && (op->flags & NCP_PROBE_F_ERROR)) {
        ncp_diag_set(&j->map_diag, NCP_ERR_SEMANTIC, cmd->line, 0,
                     "G38.%d probe move finished without contact",
                     op->flags & NCP_PROBE_F_AWAY ? 4 : 2);
        return -1;
    }
    /* the trip point, or where a move without contact ended (LinuxCNC) */
    double prog[3];
    ncp_canon_map_to_program(&n->job->map, p->tripped ? p->trip : n->job->map.pos, prog);
    memcpy(ms->probed, op->move.end, sizeof ms->probed);
    memcpy(ms->probed, prog, sizeof prog);
    ms->tripped = p->tripped;
    if (p->tripped)   /* the next move starts where the axes stopped */
        memcpy(n->job->map.pos, p->rest, sizeof n->job->map.pos);
    ncp_canon_map_to_program(&n->job->map, n->job->map.pos, ms->pos);
    ms->what |= NCP_SYNC_PROBE;
    return 0;
}

/* The interpreter's side (its thread): wait for the job thread's answer. */
static int machine_sync(void *ctx, struct ncp_machine_sync *ms)
{
    struct nck_core *n = ctx;
    struct nck_job *j = n->job;
    j->busters_asked++;
    while (atomic_load_explicit(&j->busters_done, memory_order_acquire) < j->busters_asked) {
        if (atomic_load(&j->abort) || atomic_load(&j->emit_stopped))
            return -1;
        nap_us(200);
    }
    *ms = j->answer;
    memset(&j->answer, 0, sizeof j->answer);
    return 0;
}

static int is_buster(const struct ncp_canon *op)
{
    return op->kind == NCP_C_STRAIGHT_PROBE || op->kind == NCP_C_WAIT_INPUT ||
           op->kind == NCP_C_CHANGE_TOOL;
}

static int emit_segments(void *ctx, const struct ncp_cmd *cmd);

/* Whatever stops the emit, the interpreter must not wait for an answer. */
static int emit_job(void *ctx, const struct ncp_cmd *cmd)
{
    struct nck_core *n = ctx;
    if (NCP_CMD_FILE(cmd) == 0)   /* a subroutine file's lines are not the program's */
        atomic_store_explicit(&n->job->line_read, cmd->line, memory_order_relaxed);
    int rc = emit_segments(ctx, cmd);
    if (rc)
        atomic_store(&n->job->emit_stopped, 1);
    return rc;
}

static int emit_segments(void *ctx, const struct ncp_cmd *cmd)
{
    struct nck_core *n = ctx;
    struct nck_job *j = n->job;
    if (atomic_load(&j->abort))
        return 1;
    if (cmd->text_used && !n->cross.post_prints && !n->quiet)
        (void)ncp_exec_write_prints(cmd, stderr);
    if (j->from_line && !j->reached && cmd->line >= j->from_line) {
        /* the map's position is where the skipped part left the tool */
        double target[NCP_AXES];
        memcpy(target, n->job->map.pos, sizeof target);
        j->reached = 1;
        if (restore_machine(n, cmd->line) || approach(n, cmd->line))
            return 1;
        memcpy(n->job->map.pos, target, sizeof n->job->map.pos);
    }
    int seen = j->seen_motion;
    j->seen_motion = 0;
    int busted = 0;
    struct ncp_seg seg;
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        const struct ncp_canon *op = &cmd->ops[i];
        unsigned kind = op->kind < NCP_C__COUNT ? op->kind : NCP_C_NONE;
        n->cross.calls_in[kind]++;
        if (nck_check_call(cmd, op, &j->map_diag)) {
            n->cross.calls_refused[kind]++;
            j->map_failed = 1;
            return 1;
        }
        if (n->cross.post_prints && op->kind == NCP_C_PRINT)
            post_text(n, cmd, op, NCP_EV_PRINT);
        else if (n->cross.post_prints && op->kind == NCP_C_MESSAGE)
            post_text(n, cmd, op, NCP_EV_MSG);
        else if (op->kind >= NCP_C_LOGOPEN && op->kind <= NCP_C_LOG)
            log_text(n, cmd, op);
        nck_note_state(n, op);
        int skipping = j->from_line && !j->reached;
        if (op->kind == NCP_C_STRAIGHT_PROBE && !skipping &&
            aux_add(n, NCK_AUX_PROBE, 0, op->flags, 0, cmd->line, 0))
            return 1;
        int rc = ncp_canon_map_op(&n->job->map, op, cmd->line, &seg, &j->map_diag);
        while (rc == 1) {
            if (take_seg(n, &seg))
                return 1;
            rc = ncp_canon_map_more(&n->job->map, &seg, &j->map_diag);
        }
        if (rc < 0) {
            n->cross.calls_refused[kind]++;
            j->map_failed = 1;
            return 1;
        }
        if (op->kind == NCP_C_STOP_SPEED_FEED_SYNCH && sync_flush(n))
            return 1;
        int after_pallet = i > 0 && cmd->ops[i - 1].kind == NCP_C_PALLET_SHUTTLE;
        if ((!j->from_line || j->reached) && take_aux(n, cmd, op, after_pallet))
            return 1;
        /* M100..M199: in order with motion, as LinuxCNC's task runs them */
        if (op->kind == NCP_C_USER_M && !skipping && (drain(n) || nck_user_m_run(n, cmd, op))) {
            if (j->map_diag.code != NCP_OK) {
                n->cross.calls_refused[kind]++;
                j->map_failed = 1;
            }
            return 1;
        }
        if (is_buster(op)) {
            /* skipped lines (run from line) get the stand-in's answer */
            if (!skipping && buster(n, cmd, op)) {
                if (j->map_diag.code != NCP_OK) {
                    n->cross.calls_refused[kind]++;
                    j->map_failed = 1;
                }
                return 1;
            }
            busted = 1;
        }
        n->cross.calls_acted[kind]++;
    }
    /* the interpreter asks once for a block's busters, whatever their number */
    if (busted)
        atomic_fetch_add_explicit(&j->busters_done, 1, memory_order_release);
    if (n->cross.post_prints) {   /* a serving NCK's status shows it */
        pthread_mutex_lock(&n->cross.ev_lock);
        n->cross.io.interp_line = cmd->line;
        n->cross.io.active = cmd->active;
        pthread_mutex_unlock(&n->cross.ev_lock);
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
    struct nck_core *n = arg;
    struct nck_job *j = n->job;
    struct ncp_output out = { .ctx = n, .emit = emit_job, .sync = machine_sync,
                              .threads = nck_sched_pipe_hooks(n) };
    nck_sched_enter(n, 0);
    memset(&j->diag, 0, sizeof j->diag);
    j->rc = j->interpret(j->interp_ctx, &out, &j->diag);
    push_mark(n, NCK_MSG_END);
    nck_sched_leave(n, 0);
    atomic_store(&j->finished, 1);
    return NULL;
}

static void *moves_main(void *arg)
{
    struct nck_core *n = arg;
    struct nck_job *j = n->job;
    nck_sched_enter(n, 0);
    for (int k = 0; k < j->n_moves; k++)
        if (j->moves[k].length > 1e-9 && push_seg(n, &j->moves[k]))
            break;
    push_mark(n, NCK_MSG_END);
    nck_sched_leave(n, 0);
    atomic_store(&j->finished, 1);
    return NULL;
}

/* The caller filled n->job (kind, interpret or moves, from_line); the
 * planner is idle at the map's position. */
int nck_job_start(struct nck_core *n)
{
    struct nck_job *j = n->job;
    atomic_store(&j->finished, 0);
    atomic_store(&j->abort, 0);
    atomic_store(&n->cross.job_waiting, 0);
    j->marks = 0;
    j->map_failed = 0;
    j->rc = NCP_OK;
    j->reached = 0;
    j->seen_motion = 0;
    j->aux.n = 0;
    j->aux_stop = 0;
    j->need_at_speed = 0;
    j->capped_said = 0;
    j->run.n = 0;
    atomic_store(&j->busters_done, 0);
    j->busters_asked = 0;
    atomic_store(&j->emit_stopped, 0);
    memset(&j->answer, 0, sizeof j->answer);
    j->step_used = atomic_load(&j->step_go);
    j->max_z = n->job->map.pos[2];
    memset(&j->map_diag, 0, sizeof j->map_diag);
    memcpy(j->origin, n->job->map.pos, sizeof j->origin);
    n->job->marks_base = atomic_load(&n->cross.marks_sent);
    /* the stretch the job's first END or SYNC closes */
    atomic_fetch_add_explicit(&n->cross.marks_sent, 1, memory_order_release);
    void *(*fn)(void *) = j->kind == NCK_JOB_MOVE ? moves_main : interp_main;
    const struct ncp_rt_place *pl = &n->cross.job_place;
    if (ncp_rt_start(&j->thread, pl, fn, n, NULL)) {
        atomic_fetch_sub(&n->cross.marks_sent, 1);
        j->kind = NCK_JOB_NONE;
        return -1;
    }
    j->started = 1;
    return 0;
}

void nck_job_join(struct nck_core *n)
{
    if (n->job->started)
        pthread_join(n->job->thread, NULL);
    n->job->started = 0;
}
