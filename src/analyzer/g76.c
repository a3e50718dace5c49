/* G76, the lathe threading cycle, as rs274 (convert_threading_cycle) cuts
 * it: passes at growing depth along Z, each synchronised to the spindle,
 * then the spring passes at full depth. Depths are radial (X) distances
 * from the start point; I < 0 cuts an outside thread, I > 0 bores. The
 * arithmetic follows rs274's line for line (its compound angle is scaled
 * in long double) so that every coordinate prints the same. */
#include "floor.h"
#include "stages.h"

#include <math.h>

struct ncp_g76 {
    int boring;
    double safe_x, start_y, start_z, target_z;
    double end_depth, full_threadheight;
    double pitch, taper_pitch, taper_dist;
    int entry_taper, exit_taper;
    double abc[3];
};

static void ncp_g76_move(struct ncp_analyzer *a, const struct ncp_g76 *t,
                            enum ncp_canon_kind kind, double x, double z)
{
    double p[6] = {x, t->start_y, z, t->abc[0], t->abc[1], t->abc[2]};
    ncp_an_emit6(a, kind, p);
}

static void ncp_g76_sync(struct ncp_analyzer *a, double pitch)
{
    ncp_an_emit(a, NCP_C_START_SPEED_FEED_SYNCH)->synch.per_rev = pitch;
}

/* X at `depth` below the start (or above it, boring). */
static double ncp_g76_x(const struct ncp_g76 *t, double depth)
{
    return t->boring ? t->safe_x + depth : t->safe_x - depth;
}

static void ncp_g76_pass(struct ncp_analyzer *a, const struct ncp_g76 *t, double depth,
                            double zoff)
{
    double back = t->boring ? t->safe_x + depth - t->end_depth : t->safe_x - depth + t->end_depth;
    double top = t->boring ? t->safe_x + depth - t->full_threadheight
                           : t->safe_x - depth + t->full_threadheight;
    ncp_g76_move(a, t, NCP_C_STRAIGHT_TRAVERSE, back, t->start_z - zoff);
    if (t->taper_dist != 0.0 && t->entry_taper) {
        ncp_an_emit(a, NCP_C_DISABLE_FEED_OVERRIDE);
        ncp_g76_sync(a, t->taper_pitch);
        ncp_g76_move(a, t, NCP_C_STRAIGHT_FEED, top, t->start_z - zoff);
        ncp_g76_move(a, t, NCP_C_STRAIGHT_FEED, ncp_g76_x(t, depth),
                        t->start_z - zoff - t->taper_dist);
        ncp_g76_sync(a, t->pitch);
    } else {
        ncp_g76_move(a, t, NCP_C_STRAIGHT_TRAVERSE, ncp_g76_x(t, depth), t->start_z - zoff);
        ncp_an_emit(a, NCP_C_DISABLE_FEED_OVERRIDE);
        ncp_g76_sync(a, t->pitch);
    }
    if (t->taper_dist != 0.0 && t->exit_taper) {
        ncp_g76_move(a, t, NCP_C_STRAIGHT_FEED, ncp_g76_x(t, depth),
                        t->target_z - zoff + t->taper_dist);
        ncp_g76_sync(a, t->taper_pitch);
        ncp_g76_move(a, t, NCP_C_STRAIGHT_FEED, top, t->target_z - zoff);
    } else {
        ncp_g76_move(a, t, NCP_C_STRAIGHT_FEED, ncp_g76_x(t, depth), t->target_z - zoff);
    }
    ncp_an_emit(a, NCP_C_STOP_SPEED_FEED_SYNCH);
    ncp_g76_move(a, t, NCP_C_STRAIGHT_TRAVERSE, back, t->target_z - zoff);
    ncp_an_emit(a, NCP_C_ENABLE_FEED_OVERRIDE);
}

/* Depth of cutting pass n (1, 2, ...): the first at J past I, the next ones
 * taking off ever less as the degression R grows. */
static double ncp_g76_depth(double full_dia_depth, double cut_increment, double n,
                               double degression)
{
    return full_dia_depth + cut_increment * pow(n, 1.0 / degression);
}

static double ncp_word_or(const struct ncp_words *w, char c, double absent)
{
    return NCP_HAS(w, c) ? w->v[NCP_LETTER(c)] : absent;
}

int ncp_g76_cycle(struct ncp_analyzer *a, const double *end)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    if (s->m.comp_side != 0)
        return ncp_an_error(a, col, "Cannot use G76 threading cycle with cutter radius compensation on");
    double i_number = w->v[NCP_LETTER('I')], j_number = w->v[NCP_LETTER('J')],
           k_number = w->v[NCP_LETTER('K')];
    if (i_number == 0)
        return ncp_an_error(a, col, "In G76, I must not be 0");
    if (j_number <= 0)
        return ncp_an_error(a, col, "In G76, J must be greater than 0");
    if (k_number <= j_number)
        return ncp_an_error(a, col, "In G76, K must be greater than J");
    if (s->m.lathe_diameter) {
        i_number /= 2;
        j_number /= 2;
        k_number /= 2;
    }
    struct ncp_g76 t = {
        .boring = i_number > 0.0,
        .safe_x = s->pos[NCP_X],
        .start_y = s->pos[NCP_Y],
        .start_z = s->pos[NCP_Z],
        .abc = {s->pos[NCP_A], s->pos[NCP_B], s->pos[NCP_C]},
    };
    double full_dia_depth = fabs(i_number);
    double start_depth = fabs(i_number) + fabs(j_number);
    double cut_increment = fabs(j_number);
    t.full_threadheight = fabs(k_number);
    t.end_depth = fabs(k_number) + fabs(i_number);
    t.pitch = w->v[NCP_LETTER('P')];
    double q = ncp_word_or(w, 'Q', -1.0);
    if (q == -1)
        q = 0;
    double compound_angle = (double)(q * (M_PIl / 180.0L));
    if (end[NCP_Z] > t.start_z)
        compound_angle = -compound_angle;
    /* H and L are integers to rs274 */
    int spring_cuts = NCP_HAS(w, 'H') ? ncp_trunc_int_round(w->v[NCP_LETTER('H')]) : 0;
    double degression = ncp_word_or(w, 'R', 1.0);
    if (degression < 1.0)
        degression = 1.0;
    t.taper_dist = ncp_word_or(w, 'E', 0.0);
    if (t.taper_dist < 0.0)
        t.taper_dist = 0.0;
    t.taper_pitch = t.taper_dist > 0.0
                        ? t.pitch * hypot(t.taper_dist, t.full_threadheight) / t.taper_dist
                        : t.pitch;
    if (end[NCP_Z] > t.start_z)
        t.taper_dist = -t.taper_dist;
    int taper_flags = NCP_HAS(w, 'L') ? ncp_trunc_int_round(w->v[NCP_LETTER('L')]) : 0;
    if (taper_flags < 0)
        taper_flags = 0;
    t.entry_taper = taper_flags & 1;
    t.exit_taper = taper_flags & 2;
    t.target_z = end[NCP_Z] + fabs(k_number) * tan(compound_angle);

    /* rs274 cuts until the depth reaches K, however many passes that takes:
     * with a large R (degression) or H (spring passes) that is forever. The
     * passes are counted first, against the loop guard, so a runaway cycle
     * stops before it prints anything. */
    uint32_t limit = a->cfg.max_loop_iterations ? a->cfg.max_loop_iterations
                                                : NCP_DEFAULT_MAX_LOOPS;
    double passes = 0.0;
    for (double n = 1.0, d = start_depth; d < t.end_depth && passes <= limit;
         d = ncp_g76_depth(full_dia_depth, cut_increment, ++n, degression))
        passes++;
    passes += (double)spring_cuts + 1.0;
    if (passes > limit)
        return ncp_an_error(a, col,
                            "G76 would cut more than %u passes (J, K and R set the passes to "
                            "depth, H the spring passes): runaway cycle? (raise the "
                            "limit with --max-loops N if intended)", limit);

    double pass = 1.0;
    double depth = start_depth;
    double zoff = (depth - full_dia_depth) * tan(compound_angle);
    while (depth < t.end_depth) {
        ncp_g76_pass(a, &t, depth, zoff);
        depth = ncp_g76_depth(full_dia_depth, cut_increment, ++pass, degression);
        zoff = (depth - full_dia_depth) * tan(compound_angle);
    }
    depth = t.end_depth;
    zoff = (depth - full_dia_depth) * tan(compound_angle);
    for (int k = 0; k <= spring_cuts; k++)
        ncp_g76_pass(a, &t, depth, zoff);
    double last[6] = {end[NCP_X], end[NCP_Y], end[NCP_Z], t.abc[0], t.abc[1], t.abc[2]};
    ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, last);
    s->pos[NCP_X] = end[NCP_X];
    s->pos[NCP_Y] = end[NCP_Y];
    s->pos[NCP_Z] = end[NCP_Z];
    return NCP_OK;
}
