/* Rough interpolation on the programmed feed: the path advances at a constant
 * speed (no ramps: the ACC/DEC below makes them, per axis), one record of
 * increments per rough period. Positions are kept in integer nm and every
 * record is the difference of two quantised points on the path, so the
 * records of a block sum to exactly its quantised end point. */
#include "ncpar/adcai.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ncp_adcai_rough;
static const struct ncp_seg *at(const struct ncp_adcai_rough *r, size_t k);

struct ncp_adcai_rough {
    const struct ncp_machine_cfg *cfg;
    double period;
    double filter_time;     /* the ACC/DEC's windows together, s */
    struct ncp_seg q[NCP_ADCAI_ROUGH_QUEUE];
    size_t head, count;
    int active;             /* q[head] is being interpolated */
    int finishing;
    double s, v;            /* distance along q[head] and its speed */
    long dwell_left;        /* rough periods of the dwell at q[head] */
    int64_t pos[NCP_AXES];  /* the sum of the records so far */
    struct ncp_adcai_rough_rec tag;
    /* The block that ended mid-program with nothing queued after it: the
     * corner it makes with the next is decided when that one comes, so
     * that a late interpreter cannot round a corner past its tolerance. */
    int ran_out;
    struct ncp_seg last;
};

/* The largest |d axis / d path| along s, per axis, and what of the axis's
 * acceleration v^2 curv takes at path speed v (a corner parabola's turn; 0
 * elsewhere). An arc's X Y Z take the bound of a circle of its larger radius
 * plus the helix's rise. */
static void axis_rates(const struct ncp_seg *s, double rate[NCP_AXES], double curv[NCP_AXES])
{
    double len = s->length > 0 ? s->length : 1;
    for (int j = 0; j < NCP_AXES; j++) {
        rate[j] = fabs(s->end[j] - s->start[j]) / len;
        curv[j] = 0;
    }
    if (s->kind == NCP_SEG_PARAB && s->length > 0) {
        ncp_seg_parab_rates(s, rate, curv);
        return;
    }
    if (s->kind != NCP_SEG_ARC)
        return;
    double r = fmax(s->r0, s->r1), turn = fabs(s->angle) * r + fabs(s->r1 - s->r0);
    for (int j = 0; j < 3; j++) {
        double plane = sqrt(s->u[j] * s->u[j] + s->w[j] * s->w[j]);
        rate[j] = (plane * turn + fabs(s->normal[j] * s->axial)) / len;
    }
}

double ncp_adcai_rough_speed(const struct ncp_machine_cfg *cfg, const struct ncp_seg *s)
{
    double v = s->feed;
    if (!s->angular)
        v = fmin(v, cfg->max_linear_vel);
    double rate[NCP_AXES], curv[NCP_AXES], a_plane = INFINITY;
    axis_rates(s, rate, curv);
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)) || rate[j] < 1e-12)
            continue;
        v = fmin(v, cfg->axis[j].max_vel / rate[j]);
        if (curv[j] > 1e-12)
            v = fmin(v, sqrt(cfg->axis[j].max_acc / curv[j]));
        if (s->kind == NCP_SEG_ARC && j < 3 && (s->u[j] != 0 || s->w[j] != 0))
            a_plane = fmin(a_plane, cfg->axis[j].max_acc);
    }
    double r = fmin(s->r0, s->r1);
    if (s->kind == NCP_SEG_ARC && r > 0 && isfinite(a_plane))
        v = fmin(v, sqrt(a_plane * r));
    /* a speed of 0 would never end the block: the map refuses zero feeds,
     * this only keeps a broken segment from hanging the machine */
    if (!(v > 1e-6))
        v = 1e-6;
    return v;
}

struct ncp_adcai_rough *ncp_adcai_rough_new(const struct ncp_machine_cfg *cfg, double period,
                                            const double start[NCP_AXES])
{
    if (!(period > 0))
        return NULL;
    struct ncp_adcai_rough *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->cfg = cfg;
    r->period = period;
    int n[2];
    if (ncp_adcai_windows(cfg, period, n) != 0) {
        free(r);
        return NULL;
    }
    r->filter_time = (n[0] + n[1]) * period;
    ncp_adcai_rough_reset(r, start);
    return r;
}

void ncp_adcai_rough_free(struct ncp_adcai_rough *r)
{
    free(r);
}

int ncp_adcai_rough_full(const struct ncp_adcai_rough *r)
{
    return r->count >= NCP_ADCAI_ROUGH_QUEUE;
}

size_t ncp_adcai_rough_queued(const struct ncp_adcai_rough *r)
{
    return r->count;
}

int ncp_adcai_rough_busy(const struct ncp_adcai_rough *r)
{
    return r->count > 0;
}

void ncp_adcai_rough_push(struct ncp_adcai_rough *r, const struct ncp_seg *s)
{
    if (r->count >= NCP_ADCAI_ROUGH_QUEUE)
        return;   /* the caller checks _full: a full queue takes nothing */
    r->q[(r->head + r->count) % NCP_ADCAI_ROUGH_QUEUE] = *s;
    r->count++;
}

void ncp_adcai_rough_finish(struct ncp_adcai_rough *r)
{
    r->finishing = 1;
}

void ncp_adcai_rough_restart(struct ncp_adcai_rough *r)
{
    r->finishing = 0;
}

void ncp_adcai_rough_reset(struct ncp_adcai_rough *r, const double pos[NCP_AXES])
{
    r->head = r->count = 0;
    r->active = r->finishing = r->ran_out = 0;
    r->s = r->v = 0;
    r->dwell_left = 0;
    for (int j = 0; j < NCP_AXES; j++)
        r->pos[j] = ncp_adcai_quantise(pos[j]);
    memset(&r->tag, 0, sizeof r->tag);
}

int ncp_adcai_rough_align(struct ncp_adcai_rough *r)
{
    const struct ncp_seg *s = at(r, 0);
    if (r->active || !s)
        return 0;
    /* a dwell is at its end point */
    const double *from = s->kind == NCP_SEG_DWELL ? s->end : s->start;
    int moved = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        int64_t q = ncp_adcai_quantise(from[j]);
        moved |= q != r->pos[j];
        r->pos[j] = q;
    }
    return moved;
}

void ncp_adcai_rough_position(const struct ncp_adcai_rough *r, int64_t pos[NCP_AXES])
{
    memcpy(pos, r->pos, sizeof r->pos);
}

static const struct ncp_seg *at(const struct ncp_adcai_rough *r, size_t k)
{
    return k < r->count ? &r->q[(r->head + k) % NCP_ADCAI_ROUGH_QUEUE] : NULL;
}

static void pop(struct ncp_adcai_rough *r)
{
    r->head = (r->head + 1) % NCP_ADCAI_ROUGH_QUEUE;
    r->count--;
    r->active = 0;
}

/* How far the ACC/DEC cuts inside the corner from a into b: a moving
 * average of time Tw turns a velocity step dv into a curve that passes the
 * corner at |dv| Tw / 8 (exact for one window, an upper bound for two). */
static double corner_cut(const struct ncp_adcai_rough *r, const struct ncp_seg *a,
                         const struct ncp_seg *b)
{
    double p[NCP_AXES], t1[NCP_AXES], t2[NCP_AXES], dv = 0;
    ncp_seg_eval(a, a->length, p, t1);
    ncp_seg_eval(b, 0, p, t2);
    double va = ncp_adcai_rough_speed(r->cfg, a), vb = ncp_adcai_rough_speed(r->cfg, b);
    for (int j = 0; j < NCP_AXES; j++)
        dv += (vb * t2[j] - va * t1[j]) * (vb * t2[j] - va * t1[j]);
    return sqrt(dv) * r->filter_time / 8;
}

/* Must the axes come to rest where a ends (next: what follows, NULL when
 * nothing is queued)? The ADCBI planner's stops: G61.1, dwells, the end of
 * the program (finishing with nothing after a), and G61's corners; G61 goes
 * on through a tangent joint. G64 lets the filters round a corner as far as
 * the ADCBI planner's blend may reach (P, or without P half the shorter
 * move), and stops where they would cut deeper. With nothing queued in the
 * middle of a program there is no stop: the record runs short and the
 * ACC/DEC smooths the gap, as it smooths a corner. */
static int stops_after(const struct ncp_adcai_rough *r, const struct ncp_seg *a,
                       const struct ncp_seg *next)
{
    if (a->kind == NCP_SEG_DWELL || a->term == NCP_TERM_STOP)
        return 1;
    if (!next)
        return r->finishing;
    if (next->kind == NCP_SEG_DWELL)
        return 1;
    if (a->term == NCP_TERM_CONTINUOUS) {
        double tol = a->tolerance > 0 ? a->tolerance : 0.5 * fmin(a->length, next->length);
        return corner_cut(r, a, next) > tol;
    }
    double p[NCP_AXES], t1[NCP_AXES], t2[NCP_AXES];
    ncp_seg_eval(a, a->length, p, t1);
    ncp_seg_eval(next, 0, p, t2);
    for (int j = 0; j < NCP_AXES; j++)
        if (fabs(t2[j] - t1[j]) > 1e-9)
            return 1;
    return 0;
}

static void start_head(struct ncp_adcai_rough *r)
{
    const struct ncp_seg *s = at(r, 0);
    r->active = 1;
    r->s = 0;
    if (s->kind == NCP_SEG_DWELL) {
        r->v = 0;
        r->dwell_left = (long)ceil(s->dwell / r->period - 1e-9);
    } else {
        r->v = ncp_adcai_rough_speed(r->cfg, s);
    }
    r->tag.line = s->line;
    r->tag.aux = s->aux;
    r->tag.tool_z = s->tool_z;
    r->tag.rev_rpm = s->rev_rpm;
    r->tag.motion = s->traverse ? NCP_SP_RAPID : s->kind == NCP_SEG_ARC ? NCP_SP_ARC : 0;
}

/* Advances through the segments by one period; the path point reached. */
static int advance(struct ncp_adcai_rough *r, double p[NCP_AXES])
{
    double t = r->period;
    int stop = 0;
    for (;;) {
        const struct ncp_seg *s = at(r, 0);
        if (s->kind == NCP_SEG_DWELL) {
            /* a dwell starts from rest (the stop before it) and is a record
             * of no motion per period; its last is a stop like any */
            memcpy(p, s->end, sizeof(double) * NCP_AXES);
            if (--r->dwell_left <= 0) {
                pop(r);
                stop = 1;
            }
            return stop;
        }
        double left = s->length - r->s;
        if (left > r->v * t) {
            r->s += r->v * t;
            ncp_seg_eval(s, r->s, p, NULL);
            return 0;
        }
        t -= left / r->v;
        ncp_seg_eval(s, s->length, p, NULL);
        stop = stops_after(r, s, at(r, 1));
        if (!stop && r->count == 1) {
            r->ran_out = 1;
            r->last = *s;
        }
        pop(r);
        /* a stop ends the record at the block's end point: the period's rest
         * waits while the ACC/DEC drains */
        if (stop || r->count == 0 || at(r, 0)->kind == NCP_SEG_DWELL)
            return stop;
        start_head(r);
    }
}

int ncp_adcai_rough_late_stop(struct ncp_adcai_rough *r)
{
    if (!r->ran_out || r->active || r->count == 0)
        return 0;
    r->ran_out = 0;
    return stops_after(r, &r->last, at(r, 0));
}

int ncp_adcai_rough_step(struct ncp_adcai_rough *r, struct ncp_adcai_rough_rec *out)
{
    memset(out, 0, sizeof *out);
    if (!r->active && r->count == 0) {
        out->line = r->tag.line;
        out->aux = r->tag.aux;
        out->tool_z = r->tag.tool_z;
        return 0;
    }
    if (!r->active)
        start_head(r);
    double p[NCP_AXES];
    int stop = advance(r, p);
    /* the block the period ended in */
    *out = r->tag;
    out->stop = (uint8_t)stop;
    for (int j = 0; j < NCP_AXES; j++) {
        int64_t q = ncp_adcai_quantise(p[j]);
        out->inc[j] = (int32_t)(q - r->pos[j]);
        r->pos[j] = q;
    }
    return 1;
}
