/* M70 (save the modal state), M71 (forget it), M72 (restore it) and M73
 * (save it, restored when the subroutine returns), per call level, as rs274
 * 2.9 runs them. rs274 restores by writing G-code for whatever differs and
 * executing it: a G20/G21 line first, then one line of F (%.1f), S (%.0f),
 * the differing G codes and G64 with its tolerances (%f), with the first
 * differing M code joined to it and each further M code on a line of its
 * own. The text, its rounding and its order are what rs274 prints from, so
 * they are rebuilt here the same way and run through the same reader and
 * executor as any block. The lines run in place of the M72 block: rs274
 * reads them into the block it is executing, so what that block had left to
 * do (its G codes, its motion) is dropped, and so it is here. */
#include "floor.h"
#include "stages.h"

#include "ncpar/blocks.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { M7X_VALID = 1, M7X_RESTORE_ON_RETURN = 2 };

/* rs274's active_g_codes / active_m_codes slots that a restore looks at */
enum { G_PLANE = 3, G_COMP, G_UNITS, G_DIST, G_FEEDMODE, G_COORD, G_TLO, G_RETRACT,
       G_CONTROL, G_SPINDLE = 13, G_IJK, G_LATHE, G_SLOTS };
enum { M_SPINDLE = 2, M_MIST = 4, M_FLOOD, M_OVERRIDE, M_ADAPTIVE, M_HOLD, M_SLOTS };

struct ncp_m7x_state {
    int g[G_SLOTS], m[M_SLOTS];
    double feed, speed, tol, naive;
};

struct ncp_m7x_frame {
    int status;
    struct ncp_m7x_state s;
};

void ncp_analyzer_active_codes(const struct ncp_analyzer *a, struct ncp_active_codes *o)
{
    const struct ncp_modal *m = &a->st.m;
    int tlo = 0;
    for (int ax = 0; ax < NCP_NAX; ax++)
        tlo |= a->st.tlo[ax] != 0.0;
    o->g[NCP_AG_MOTION] = (int16_t)m->motion;
    o->g[NCP_AG_PLANE] = m->plane == 0 ? NCP_G17 : m->plane == 1 ? NCP_G19 : NCP_G18;
    o->g[NCP_AG_DIST] = m->incremental ? NCP_G91 : NCP_G90;
    o->g[NCP_AG_ARCDIST] = m->arc_incremental ? NCP_G91_1 : NCP_G90_1;
    o->g[NCP_AG_FEEDMODE] = m->feed_mode == 1 ? NCP_G93 : m->feed_mode == 0 ? NCP_G94 : NCP_G95;
    o->g[NCP_AG_UNITS] = m->inches ? NCP_G20 : NCP_G21;
    o->g[NCP_AG_COMP] = m->comp_side == 1 ? NCP_G41 : m->comp_side == 2 ? NCP_G42 : NCP_G40;
    o->g[NCP_AG_TLO] = tlo ? NCP_G43 : NCP_G49;
    o->g[NCP_AG_RETRACT] = m->retract_r ? NCP_G99 : NCP_G98;
    o->g[NCP_AG_COORD] =
        (int16_t)(m->origin < 7 ? NCP_G53 + 10 * m->origin : NCP_G59 + (m->origin - 6));
    o->g[NCP_AG_CONTROL] = m->control == 2 ? NCP_G64 : m->control == 1 ? NCP_G61 : NCP_G61_1;
    o->g[NCP_AG_SPINDLE] = m->css ? NCP_G96 : NCP_G97;
    o->g[NCP_AG_LATHE] = m->lathe_diameter ? NCP_G7 : NCP_G8;
    o->m[NCP_AM_SPINDLE] = m->spindle_dir == 0 ? 5 : m->spindle_dir == 1 ? 3 : 4;
    o->m[NCP_AM_MIST] = m->mist ? 7 : m->flood ? -1 : 9;
    o->m[NCP_AM_FLOOD] = m->flood ? 8 : -1;
    o->m[NCP_AM_OVERRIDE] = m->feed_override ? 48 : 49; /* 2.9 looks at the feed override only */
    o->g64_p = m->g64_p;
    o->g64_q = m->g64_q;
}

/* rs274's restore reads the same codes as the display, in its own slots. */
static void ncp_m7x_snapshot(const struct ncp_analyzer *a, struct ncp_m7x_state *o)
{
    const struct ncp_modal *m = &a->st.m;
    struct ncp_active_codes ac;
    ncp_analyzer_active_codes(a, &ac);
    for (int i = 0; i < G_SLOTS; i++)
        o->g[i] = -1;
    for (int i = 0; i < M_SLOTS; i++)
        o->m[i] = -1;
    o->g[G_PLANE] = ac.g[NCP_AG_PLANE];
    o->g[G_COMP] = ac.g[NCP_AG_COMP];
    o->g[G_UNITS] = ac.g[NCP_AG_UNITS];
    o->g[G_DIST] = ac.g[NCP_AG_DIST];
    o->g[G_FEEDMODE] = ac.g[NCP_AG_FEEDMODE];
    o->g[G_COORD] = ac.g[NCP_AG_COORD];
    o->g[G_TLO] = ac.g[NCP_AG_TLO];
    o->g[G_RETRACT] = ac.g[NCP_AG_RETRACT];
    o->g[G_CONTROL] = ac.g[NCP_AG_CONTROL];
    o->g[G_SPINDLE] = ac.g[NCP_AG_SPINDLE];
    o->g[G_IJK] = ac.g[NCP_AG_ARCDIST];
    o->g[G_LATHE] = ac.g[NCP_AG_LATHE];
    o->m[M_SPINDLE] = ac.m[NCP_AM_SPINDLE];
    o->m[M_MIST] = ac.m[NCP_AM_MIST];
    o->m[M_FLOOD] = ac.m[NCP_AM_FLOOD];
    o->m[M_OVERRIDE] = ac.m[NCP_AM_OVERRIDE];
    o->m[M_ADAPTIVE] = m->adaptive ? NCP_M52 : -1;
    o->m[M_HOLD] = m->feed_hold ? NCP_M53 : -1;
    o->feed = a->st.feed;
    o->speed = a->st.speed;
    o->tol = m->g64_p;
    o->naive = m->g64_q;
}

/* Call level `level`'s frame, the table grown to hold it; NULL (and the
 * analyzer's error set) when out of memory. */
static struct ncp_m7x_frame *ncp_m7x_frame_at(struct ncp_analyzer *a, int level)
{
    if (level >= a->m7x_cap) {
        int cap = level + 8;
        struct ncp_m7x_frame *f = realloc(a->m7x, (size_t)cap * sizeof *f);
        if (!f) {
            ncp_an_error(a, 0, "out of memory");
            return NULL;
        }
        memset(f + a->m7x_cap, 0, (size_t)(cap - a->m7x_cap) * sizeof *f);
        a->m7x = f;
        a->m7x_cap = cap;
    }
    return &a->m7x[level];
}

/* One line of restore text, read and executed like a block of the program
 * (the read-back after a probe or tool change included, as rs274's read). */
static int ncp_m7x_exec_line(struct ncp_analyzer *a, const char *text)
{
    if (!a->m7x_block) {
        a->m7x_block = malloc(sizeof *a->m7x_block);
        if (!a->m7x_block)
            return ncp_an_error(a, 0, "out of memory");
    }
    struct ncp_block *b = a->m7x_block;
    ncp_blocks_lex_text(text, strlen(text), a->line, a->blk ? a->blk->offset : 0, b);
    if (b->err.code != NCP_OK) {
        a->err = b->err;
        return b->err.code;
    }
    return a->execute(a, b);
}

/* Appends what snprintf wrote (n) to a text of length *len in cap bytes. */
static void ncp_m7x_grow(size_t *len, size_t cap, int n)
{
    if (n > 0)
        *len = *len + (size_t)n < cap ? *len + (size_t)n : cap;
}

#define M7X_PUT(...) \
    ncp_m7x_grow(&len, cap, snprintf(buf + len, len < cap ? cap - len : 0, __VA_ARGS__))

/* rs274's gen_settings + gen_m_codes: the text that brings `cur` to `saved`. */
static void ncp_m7x_text(const struct ncp_m7x_state *cur, const struct ncp_m7x_state *saved,
                         char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    int g64_changed = saved->tol != cur->tol || saved->naive != cur->naive;
    if (saved->feed != cur->feed)
        M7X_PUT(" F%.1f", saved->feed);
    if (saved->speed != cur->speed)
        M7X_PUT(" S%.0f", saved->speed);
    for (int i = G_PLANE; i < G_SLOTS; i++) {
        int v = saved->g[i];
        if (i == G_UNITS || v == cur->g[i] || v == -1)
            continue;
        if (i == G_CONTROL && v == NCP_G64)
            g64_changed = 1;
        else if (v % 10)
            M7X_PUT(" G%d.%d", v / 10, v % 10);
        else
            M7X_PUT(" G%d", v / 10);
    }
    if (saved->g[G_CONTROL] == NCP_G64 && g64_changed) {
        if (saved->tol < 0)
            M7X_PUT(" G64");
        else if (saved->naive < 0)
            M7X_PUT(" G64 P%f", saved->tol);
        else
            M7X_PUT(" G64 P%f Q%f", saved->tol, saved->naive);
    }
    static const int m_slots[] = {M_SPINDLE, M_MIST, M_FLOOD, M_OVERRIDE, M_ADAPTIVE, M_HOLD};
    for (size_t k = 0; k < sizeof m_slots / sizeof m_slots[0]; k++) {
        int i = m_slots[k];
        if (saved->m[i] != cur->m[i] && saved->m[i] != -1)
            M7X_PUT("M%d\n", saved->m[i]);
    }
}

/* rs274's restore_settings from the frame of call level `from`. */
static int ncp_m7x_restore(struct ncp_analyzer *a, int from)
{
    const struct ncp_m7x_frame *fr = ncp_m7x_frame_at(a, from);
    if (!fr)
        return a->err.code;
    struct ncp_m7x_state cur;
    ncp_m7x_snapshot(a, &cur);
    int ran = 0; /* the flag is set once all lines ran: each runs as a whole block */
    if (cur.g[G_UNITS] != fr->s.g[G_UNITS]) {
        ran = 1;
        char units[8];
        snprintf(units, sizeof units, "G%d", fr->s.g[G_UNITS] / 10);
        if (ncp_m7x_exec_line(a, units) != NCP_OK)
            return ncp_an_error(a, 0, "M7x: restore_settings G20/G21 failed: ''");
        ncp_m7x_snapshot(a, &cur);
    }
    char text[512];
    ncp_m7x_text(&cur, &fr->s, text, sizeof text);
    for (char *line = text; *line;) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        if (*line) {
            ran = 1;
            if (ncp_m7x_exec_line(a, line) != NCP_OK) {
                char why[NCP_DIAG_MSG_MAX];
                snprintf(why, sizeof why, "%s", a->err.msg);
                return ncp_an_error(a, 0, "M7x: restore_settings failed executing: '%s': %s",
                                    line, why);
            }
        }
        if (!nl)
            break;
        line = nl + 1;
    }
    a->block_consumed = ran;
    return NCP_OK;
}

int ncp_m7x_run(struct ncp_analyzer *a, int m)
{
    int level = a->flow ? ncp_flow_call_depth(a->flow) : 0;
    struct ncp_m7x_frame *fr = ncp_m7x_frame_at(a, level);
    if (!fr)
        return a->err.code;
    if (m == NCP_M70 || m == NCP_M73) {
        ncp_m7x_snapshot(a, &fr->s);
        fr->status |= M7X_VALID;
        if (m == NCP_M73 && level > 0) /* at level 0 rs274 only warns: nothing returns there */
            fr->status |= M7X_RESTORE_ON_RETURN;
        return NCP_OK;
    }
    if (m == NCP_M71) {
        fr->status &= ~M7X_VALID;
        return NCP_OK;
    }
    if (!(fr->status & M7X_VALID))
        return ncp_an_error(a, a->w.mcol[NCP_MG_SPINDLE],
                            "Cannot restore context from invalid stack frame - missing M70/M73?");
    return ncp_m7x_restore(a, level);
}

static void ncp_m7x_entered(void *ctx, int level)
{
    struct ncp_analyzer *a = ctx;
    struct ncp_m7x_frame *fr = ncp_m7x_frame_at(a, level);
    if (fr)
        fr->status = 0;
}

static void ncp_m7x_left(void *ctx, int level)
{
    struct ncp_analyzer *a = ctx;
    if (level < a->m7x_cap && (a->m7x[level].status & (M7X_VALID | M7X_RESTORE_ON_RETURN)) ==
                                  (M7X_VALID | M7X_RESTORE_ON_RETURN))
        a->m7x_restore_from = level;
}

struct ncp_flow_frames ncp_m7x_hooks(struct ncp_analyzer *a)
{
    return (struct ncp_flow_frames){a, ncp_m7x_entered, ncp_m7x_left};
}

/* The restore a return or endsub left: rs274 runs it on that line, before
 * anything after it is read, so it runs before the next block or the next
 * parameter an O-word line reads. */
int ncp_m7x_pending(struct ncp_analyzer *a)
{
    if (a->m7x_restore_from < 0)
        return NCP_OK;
    int from = a->m7x_restore_from;
    a->m7x_restore_from = -1;
    const struct ncp_block *blk = a->blk;
    int rc = ncp_m7x_restore(a, from);
    a->blk = blk;
    a->block_consumed = 0;
    if (rc == NCP_OK)
        rc = ncp_an_commit(a);
    return rc;
}

/* A new run: no level holds a saved state, no restore is pending. */
void ncp_m7x_reset(struct ncp_analyzer *a)
{
    if (a->m7x)
        memset(a->m7x, 0, (size_t)a->m7x_cap * sizeof *a->m7x);
    a->m7x_restore_from = -1;
    a->block_consumed = 0;
}

void ncp_m7x_free(struct ncp_analyzer *a)
{
    free(a->m7x);
    free(a->m7x_block);
    a->m7x = NULL;
    a->m7x_block = NULL;
    a->m7x_cap = 0;
}
