/* Time scaling of the setpoint stream. The position loop reads the stream at a
 * rate r (setpoints per period, 0..1), interpolating between neighbouring
 * samples, so it can slow down and stop *along the path* when the ring runs
 * low (a late planner thread) and speed up again when it refills: no jump in
 * position. The same mechanism carries live feed override and feed hold. At
 * r = 1 the output is the stream itself, sample for sample.
 *
 * What reading at a rate does: with the stream's own velocity V, acceleration
 * A and jerk J on an axis, the output has r V, r^2 A + rd V and
 * r^3 J + 3 r rd A + rdd V (rd, rdd: the rate's first and second derivative).
 *
 * Trapezoid profile: r moves linearly, at a path deceleration (rd v) of half
 * the weakest axis; each step is checked on the output's second difference
 * per axis and shortened until it fits, keeping r as the fallback (which only
 * resamples the stream). Between samples the output is a straight line.
 *
 * S-curve profile: r is driven like a jerk-limited axis. Budgets (path
 * terms, v = the stream's speed now or over the look-ahead, whichever is
 * higher): rdd v <= a quarter of the weakest axis's MAX_JERK; |rd| <=
 * min(MAX_JERK / MAX_ACCELERATION) / 12, so that 3 r rd A stays within
 * another quarter; rd v <= half the weakest axis's MAX_ACCELERATION; and per
 * axis rd V <= MAX_ACCELERATION - r'^2 A', where A' is the largest stream
 * acceleration of the same sign within the time a rate change needs to ease
 * off (decel / jerk, read ahead in the ring without popping it; beyond what
 * the ring holds, grown at the axis's jerk), and r' the rate r reaches
 * meanwhile. r is
 * steered so that rd is back to 0 when r reaches its target: holds, resumes,
 * override steps and underrun slow-downs start and end with zero added
 * acceleration. Each step is then checked on the output's second and third
 * differences per axis; if it does not fit, the step keeps rd, eases rd off at
 * the rate jerk, or keeps r, whichever fits first (else the least excess).
 * Half of each axis's jerk is left to the stream, which is what a line plans
 * with. This is a bound by construction only where the stream stays within
 * its share; elsewhere the per-step check is what holds the limits, and
 * where no step fits (the plan at an axis's full jerk just as a hold comes)
 * the least excess is taken. Tested from the trace, with no tolerance beyond
 * the print rounding (tests/unit/test_motion_limits.c; the `motion` section
 * of make test, which holds, resumes and steps the override every 0.35 s on
 * generated programs; 80 such programs checked while writing this): velocity,
 * acceleration and jerk within the limits. The braking distance of a hold
 * from v is that of a jerk-limited stop at the budgets above (the test
 * computes it); a hold that meets the plan at full acceleration the same way
 * waits until that phase is over. A virtual clock waits for the look-ahead
 * to be in the ring (ncp_scaler_wants), so its runs are deterministic. Between
 * samples the output follows the quintic below even at the servo rate: a
 * straight line between samples read at a fractional rate would step the
 * velocity at every sample.
 *
 * A sample at rest (an exact stop) is landed on, never passed between two
 * periods, so G61 end points stay exact after a rate change.
 *
 * Fine interpolation (S-curve, or any profile when the planner's rough
 * period is ratio k > 1 servo periods): the read position advances r/k
 * samples per period, and between two samples the output follows the quintic
 * Hermite curve through their positions, velocities (v * dir) and
 * accelerations. The acceleration at a sample is the end acceleration of the
 * cubic through it and the sample before (positions and velocities), 0 at
 * rest; both intervals meeting at a sample use the same value, so position,
 * velocity and acceleration are continuous and the third difference of the
 * servo output is the jerk of the quintic pieces. The curve reproduces the
 * planned motion exactly while that is a polynomial of degree <= 3 over the
 * two intervals (cruise, a constant-acceleration or constant-jerk phase), so
 * nothing lags; the samples themselves (every exact-stop end point among
 * them) are passed exactly. Where the planned jerk or acceleration changes
 * inside an interval the quintic overshoots the plan; the planner keeps 3/5
 * of the accelerations with fine interpolation (src/motion/planner.c,
 * fine_ipo_margins), and tests/unit/test_motion_ipo.c checks acceleration
 * and (S-curve) jerk of the servo output against the full limits (measured:
 * jerk at 0.73 of the limit at a 4:1 ratio on its corner program).
 * Chord error on an arc of radius R, theta = v Tp / R turned per rough
 * period: below R theta^4 / 384 at constant speed (the cubic's bound), far
 * below the R theta^2 / 8 of a straight line between the samples.
 * The real-time path stays free of allocation and locks: a few multiplies
 * per axis, and with the S-curve a look-ahead over decel / jerk / Tp samples
 * (about 40 at the shipped limits).
 */
#include "ncpar/motion.h"
#include "ncpar/rt.h"

#include <math.h>
#include <string.h>

void ncp_scaler_init(struct ncp_scaler *s, const double start[NCP_AXES], double decel,
                     double period)
{
    memset(s, 0, sizeof *s);
    memcpy(s->a.pos, start, sizeof s->a.pos);
    s->b = s->a;
    s->z = s->a;
    s->r = 1;
    s->decel = decel;
    s->period = period;
    for (int j = 0; j < NCP_AXES; j++) {
        s->amax[j] = INFINITY;
        s->jmax[j] = INFINITY;
    }
    s->ratio = 1;
    s->tp = period;
    s->rd_cap = INFINITY;
}

void ncp_scaler_limits(struct ncp_scaler *s, const struct ncp_machine_cfg *cfg)
{
    double jmin = INFINITY, ja = INFINITY;
    for (int j = 0; j < NCP_AXES; j++) {
        s->amax[j] = cfg->axis[j].max_acc;
        if (cfg->profile == NCP_PROFILE_SCURVE && cfg->axis[j].max_jerk > 0) {
            s->jmax[j] = cfg->axis[j].max_jerk;
            jmin = fmin(jmin, s->jmax[j]);
            ja = fmin(ja, s->jmax[j] / s->amax[j]);
        }
    }
    /* A quarter of the weakest axis's jerk for rdd v, a quarter for 3 r rd A
     * (the stream's acceleration A turned by the rate change), half left to
     * the stream's own (a line plans with half of an axis's jerk). */
    s->jerk = isfinite(jmin) ? 0.25 * jmin : 0;
    s->rd_cap = isfinite(jmin) ? 0.25 * ja / 3 : INFINITY;
}

void ncp_scaler_set_ratio(struct ncp_scaler *s, int ratio)
{
    s->ratio = ratio < 1 ? 1 : ratio;
    s->tp = s->period * s->ratio;
}

/* Cycles needed to bring the path speed to rest at the scaler's deceleration
 * (and jerk). */
double ncp_scaler_stop_cycles(const struct ncp_scaler *s)
{
    double vs = fmax(s->a.v, s->b.v), v = s->r * vs;
    double a = fmin(s->decel, s->rd_cap * vs), t = v / a;
    if (s->jerk > 0)
        t = v > a * a / s->jerk ? t + a / s->jerk : 2 * sqrt(v / s->jerk);
    return t / s->period;
}

static double stream_speed(const struct ncp_scaler *s)
{
    return fmax(s->a.v, s->b.v);
}

/* The path speed the S-curve rate budgets are divided by: the stream's now or
 * within the look-ahead, whichever is higher; below a crawl the rate may
 * change no faster than at it (an r changing fast on a stream at rest would
 * be a jolt once the stream moves). */
static double rate_speed(const struct ncp_scaler *s)
{
    return fmax(fmax(stream_speed(s), s->vpath_ahead), s->decel * s->decel / s->jerk);
}

/* Trapezoid: r moves linearly towards target. */
static double ramp(const struct ncp_scaler *s, double target)
{
    double vs = stream_speed(s);
    double dr = vs > 1e-9 ? s->decel * s->period / vs : 1.0;

    return target > s->r ? fmin(target, s->r + dr) : fmax(target, s->r - dr);
}

/* S-curve: the next r on a jerk-limited approach to target. rd may change by
 * g T per period, and is never more than what still stops at target with
 * that jerk: a stop from rd covers rd^2 / 2g plus its discrete steps. */
static double track(const struct ncp_scaler *s, double target)
{
    const double T = s->period;
    double vs = rate_speed(s);
    double rd_max = fmin(s->rd_cap, s->decel / vs), g = s->jerk / vs;
    /* the room the stream's own acceleration leaves each axis over the time
     * it takes to ease rd off again (s->ahead) */
    double e = target - s->r, ae = fabs(e);
    for (int j = 0; j < NCP_AXES; j++) {
        double vj = fmax(vs * fabs(s->b.dir[j]), s->vahead[j]);
        if (vj <= 1e-9)
            continue;
        /* the stream's acceleration the change adds to (same sign as rd V),
         * at the rate r grows to while rd eases off */
        int up = (e > 0) == (s->b.dir[j] >= 0);
        double r_then = e > 0 ? fmin(1.0, s->r + fabs(s->rd) * s->decel / s->jerk) : s->r;
        double stream = r_then * r_then * (up ? s->ahead[j] : s->behind[j]);
        rd_max = fmin(rd_max, fmax(0.0, s->amax[j] - stream) / vj);
    }
    if (ae < 1e-12 && fabs(s->rd) <= g * T)
        return target;
    double reach = g * (sqrt(2.25 * T * T + 2 * ae / g) - 1.5 * T);
    double want = copysign(fmin(rd_max, reach), e);
    double rd = s->rd + fmax(-g * T, fmin(g * T, want - s->rd));
    double r = s->r + rd * T;
    /* the last bit, or a step that would carry r across its target */
    if ((e > 0 && r >= target) || (e < 0 && r <= target) || fabs(target - r) < 1e-12)
        return target;
    return fmin(1.0, fmax(0.0, r));
}

/* Acceleration at sample b: the end acceleration of the cubic through a and b
 * (their positions and velocities) over tp; exact for motion of degree <= 3. */
static void knot_acc(const struct ncp_setpoint *a, const struct ncp_setpoint *b, double tp,
                     double acc[NCP_AXES])
{
    for (int j = 0; j < NCP_AXES; j++)
        acc[j] = b->v == 0 ? 0
                           : (6 * (a->pos[j] - b->pos[j]) +
                              tp * (2 * a->v * a->dir[j] + 4 * b->v * b->dir[j])) / (tp * tp);
}

/* Quintic Hermite between a and b (z: the sample before a, for a's acceleration). */
static void quintic(const struct ncp_setpoint *z, const struct ncp_setpoint *a,
                    const struct ncp_setpoint *b, double f, double tp, double pos[NCP_AXES])
{
    if (f <= 0 || f >= 1) {
        memcpy(pos, f <= 0 ? a->pos : b->pos, sizeof a->pos);
        return;
    }
    double f2 = f * f, f3 = f2 * f, f4 = f3 * f, f5 = f4 * f;
    double h0 = 1 - 10 * f3 + 15 * f4 - 6 * f5, h5 = 1 - h0;
    double h1 = f - 6 * f3 + 8 * f4 - 3 * f5, h4 = -4 * f3 + 7 * f4 - 3 * f5;
    double h2 = 0.5 * (f2 - 3 * f3 + 3 * f4 - f5), h3 = 0.5 * (f3 - 2 * f4 + f5);
    double acc_a[NCP_AXES], acc_b[NCP_AXES];
    knot_acc(z, a, tp, acc_a);
    knot_acc(a, b, tp, acc_b);
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = h0 * a->pos[j] + h5 * b->pos[j] +
                 tp * (h1 * a->v * a->dir[j] + h4 * b->v * b->dir[j]) +
                 tp * tp * (h2 * acc_a[j] + h3 * acc_b[j]);
}

/* Output at read position f in [a, b] (f > 1: in [b, c]). */
static void blend(const struct ncp_scaler *s, double f, double pos[NCP_AXES])
{
    int next = f > 1;
    const struct ncp_setpoint *z = next ? &s->a : &s->z, *a = next ? &s->b : &s->a,
                              *b = next ? &s->c : &s->b;
    if (next)
        f -= 1.0;
    if (s->ratio > 1 || s->jerk > 0) {
        quintic(z, a, b, f, s->tp, pos);
        return;
    }
    /* trapezoid at the servo rate: straight between samples, whose fixed
     * weights at r = 1 keep every difference within the stream's */
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = f <= 0 ? a->pos[j] : f >= 1 ? b->pos[j] : a->pos[j] + f * (b->pos[j] - a->pos[j]);
}

/* Output position if this period advances the read position by r; -1 when
 * that needs a sample the ring has not delivered. */
static int probe(const struct ncp_scaler *s, double r, double pos[NCP_AXES])
{
    double f = s->f + r / s->ratio;
    if (f > 1.0 && !s->have_c)
        return -1;
    blend(s, f, pos);
    return 0;
}

/* How far the output at rate r exceeds the limits, as the worst fraction of
 * an axis's limit over (<= 0: fits): second difference against MAX_ACCELERATION,
 * third difference against MAX_JERK (S-curve). */
static double excess(const struct ncp_scaler *s, double r)
{
    double pos[NCP_AXES], worst = -INFINITY;
    if (s->nlast < 2 || probe(s, r, pos) != 0)
        return 0;
    double T = s->period, T2 = T * T, T3 = T2 * T;
    for (int j = 0; j < NCP_AXES; j++) {
        double acc = fabs(pos[j] - 2 * s->last[0][j] + s->last[1][j]) / T2;
        worst = fmax(worst, acc / s->amax[j] - (1 + 1e-9));
        if (s->nlast < 3 || !isfinite(s->jmax[j]))
            continue;
        double jerk = fabs(pos[j] - 3 * s->last[0][j] + 3 * s->last[1][j] - s->last[2][j]) / T3;
        worst = fmax(worst, jerk / s->jmax[j] - (1 + 1e-9));
    }
    return worst;
}

/* The rate nearest the wanted one whose output keeps every axis's limits.
 * Fallbacks, in order: keep changing r as in the last period (no added
 * jerk), ease the change off at the rate jerk, keep r (no added
 * acceleration); if none fits, the candidate that exceeds least. */
static double govern(const struct ncp_scaler *s, double want)
{
    double e_want = excess(s, want);
    if (e_want <= 0)
        return want;
    double cands[3] = { s->r, s->r, s->r };
    int nc = 1;
    if (s->jerk > 0) {
        /* easing rd off at the rate jerk takes the rate change's share of the
         * acceleration away without a jerk beyond its budget */
        const double T = s->period;
        double g = s->jerk / rate_speed(s);
        double shed = s->rd > 0 ? fmax(0, s->rd - g * T) : fmin(0, s->rd + g * T);
        cands[0] = fmin(1.0, fmax(0.0, s->r + s->rd * T));
        cands[1] = fmin(1.0, fmax(0.0, s->r + shed * T));
        nc = 3;
    }
    double ok = -1, best = want, e_best = e_want;
    for (int i = 0; i < nc && ok < 0; i++) {
        double e = excess(s, cands[i]);
        if (e <= 0)
            ok = cands[i];
        else if (e < e_best) {
            best = cands[i];
            e_best = e;
        }
    }
    if (ok < 0)
        return best;
    double bad = want;
    for (int k = 0; k < 30; k++) {
        double mid = 0.5 * (ok + bad);
        if (excess(s, mid) <= 0)
            ok = mid;
        else
            bad = mid;
    }
    return ok;
}

static void remember(struct ncp_scaler *s, const double pos[NCP_AXES])
{
    memmove(s->last[1], s->last[0], 2 * sizeof s->last[0]);
    memcpy(s->last[0], pos, sizeof s->last[0]);
    if (s->nlast < 3)
        s->nlast++;
}

/* The slot i places behind the consumer's next one, or NULL: the consumer may
 * read the slots between its head and the producer's tail in place. */
static const struct ncp_setpoint *peek(struct ncp_spsc *ring, size_t i, size_t avail)
{
    if (i >= avail)
        return NULL;
    size_t h = atomic_load_explicit(&ring->head, memory_order_relaxed);
    return (const struct ncp_setpoint *)(void *)(ring->buf + ((h + i) & ring->mask) * ring->elem);
}

/* Largest acceleration either way and |velocity| per axis of the stream
 * (second differences of its samples) from a to as far as a rate change takes
 * to ease off (decel/jerk), as far as the ring holds it. */
static void look_ahead(struct ncp_scaler *s, struct ncp_spsc *ring)
{
    size_t h = atomic_load_explicit(&ring->head, memory_order_relaxed);
    size_t avail = atomic_load_explicit(&ring->tail, memory_order_acquire) - h;
    size_t n = (size_t)ceil(s->decel / s->jerk / s->tp) + 2;
    const struct ncp_setpoint *p0 = &s->a, *p1 = &s->b, *p2 = s->have_c ? &s->c : NULL;
    double tp2 = s->tp * s->tp;
    for (int j = 0; j < NCP_AXES; j++)
        s->ahead[j] = s->behind[j] = s->vahead[j] = 0;
    s->vpath_ahead = 0;
    for (size_t i = 0; p2 && i <= n; i++) {
        s->vpath_ahead = fmax(s->vpath_ahead, p2->v);
        for (int j = 0; j < NCP_AXES; j++) {
            double acc = (p2->pos[j] - 2 * p1->pos[j] + p0->pos[j]) / tp2;
            s->ahead[j] = fmax(s->ahead[j], acc);
            s->behind[j] = fmax(s->behind[j], -acc);
            s->vahead[j] = fmax(s->vahead[j], p2->v * fabs(p2->dir[j]));
        }
        p0 = p1;
        p1 = p2;
        p2 = peek(ring, i, avail);
        if (!p2 && i < n && p1->v > 0) {
            /* the ring holds less than the window: beyond it the stream's
             * acceleration may grow at most at the axis's jerk */
            double rest = (double)(n - i) * s->tp;
            for (int j = 0; j < NCP_AXES; j++) {
                s->ahead[j] = fmin(s->amax[j], s->ahead[j] + s->jmax[j] * rest);
                s->behind[j] = fmin(s->amax[j], s->behind[j] + s->jmax[j] * rest);
            }
        }
    }
}

size_t ncp_scaler_wants(const struct ncp_scaler *s, size_t capacity)
{
    if (s->jerk <= 0)
        return 1;
    size_t n = (size_t)ceil(s->decel / s->jerk / s->tp) + 2;
    return n < capacity / 2 ? n : capacity / 2 > 1 ? capacity / 2 : 1;
}

static double next_rate(const struct ncp_scaler *s, double target)
{
    if (s->jerk > 0)
        return govern(s, track(s, target));
    return govern(s, ramp(s, target));
}

int ncp_scaler_step(struct ncp_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out)
{
    int dry = 0, read = 0;
    double f0 = s->f;
    if (!s->have_c)
        s->have_c = ncp_spsc_pop(ring, &s->c) == 0;
    if (s->jerk > 0)
        look_ahead(s, ring);
    double r = next_rate(s, target);
    s->rd = (r - s->r) / s->period;
    s->r = r;
    s->f += s->r / s->ratio;
    /* a whole number of steps must land on the sample, not just below it;
     * and a sample at rest (an exact stop) is landed on, not passed between
     * periods: the read position is whole again from there */
    if ((s->ratio > 1 && fabs(s->f - 1.0) < 1e-9) || (s->f > 1.0 && s->b.v == 0))
        s->f = 1.0;
    if (s->f >= 1.0) {
        if (!s->have_c) {
            s->f = 1.0;
            dry = s->r > 0 && s->b.v > 0;
            s->r = 0;
            s->rd = 0;
        } else {
            s->z = s->a;
            s->a = s->b;
            s->b = s->c;
            s->b_counted = 0;
            s->f -= 1.0;
            read = 1;
            s->have_c = ncp_spsc_pop(ring, &s->c) == 0;
        }
    }
    if (s->f >= 1.0 && (s->b.flags & NCP_SP_END) && !s->b_counted) {
        s->ends++;
        s->b_counted = 1;
    }
    s->adv = read + s->f - f0;
    double f = s->f;
    blend(s, f, out->pos);
    memcpy(out->dir, s->b.dir, sizeof out->dir);
    out->v = s->r * (s->a.v + f * (s->b.v - s->a.v));
    const struct ncp_setpoint *near = f < 0.5 ? &s->a : &s->b;
    out->line = near->line;
    out->tool_z = near->tool_z;
    out->rev_rpm = near->rev_rpm;
    /* machine functions are due once the read position leaves a towards b */
    out->aux = f <= 0 ? s->a.aux : s->b.aux;
    out->flags = (f <= 0 ? s->a.flags : f >= 1 ? s->b.flags : 0) & ~(uint32_t)NCP_SP_MOTION_MASK;
    out->flags |= near->flags & NCP_SP_RAPID;
    /* on an arc only between two samples of the same arc: across a segment
     * boundary the point is on neither piece */
    if (f <= 0 || f >= 1 || (s->a.line == s->b.line && (s->a.flags & s->b.flags & NCP_SP_ARC)))
        out->flags |= near->flags & NCP_SP_ARC;
    remember(s, out->pos);
    return dry ? -1 : 0;
}

void ncp_scaler_rebase(struct ncp_scaler *s, const double pos[NCP_AXES])
{
    struct ncp_scaler keep = *s;
    ncp_scaler_init(s, pos, keep.decel, keep.period);
    s->r = 0;
    s->jerk = keep.jerk;
    s->rd_cap = keep.rd_cap;
    s->ratio = keep.ratio;
    s->tp = keep.tp;
    memcpy(s->amax, keep.amax, sizeof s->amax);
    memcpy(s->jmax, keep.jmax, sizeof s->jmax);
}

void ncp_scaler_jump(struct ncp_scaler *s, const double delta[NCP_AXES])
{
    /* the stop is landed on: a (read position 0) or b (1) */
    int b_before = s->f >= 1.0;
    for (int j = 0; j < NCP_AXES; j++) {
        s->z.pos[j] += delta[j];
        s->a.pos[j] += delta[j];
        if (b_before)
            s->b.pos[j] += delta[j];
        for (int k = 0; k < 3; k++)
            s->last[k][j] += delta[j];
    }
}
