/* The joints along a segment: the planner plans the axes (the tool tip in
 * the work's frame); through a non-trivial kinematics the joints follow
 * curved paths at speeds the axes do not show, so their limits are checked
 * and kept here by sampling the segment through the inverse transform. */
#include "ncpar/motion.h"

#include <math.h>

/* Samples per segment: a turn of the table swings the joints on circles, so
 * one sample every half degree (a chord then strays R (1 - cos 0.25 deg),
 * under 2 um at R = 200 mm, from the circle: the position loop's own check
 * catches the rest); straight moves at a fixed tilt are linear in the joints. */
static int samples(const struct ncp_seg *s)
{
    double turn = 0;
    for (int i = 3; i < 6; i++)
        turn = fmax(turn, fabs(s->end[i] - s->start[i]));
    if (s->kind == NCP_SEG_ARC)
        turn = fmax(turn, fabs(s->angle) * 180 / M_PI);
    double n = ceil(turn / 0.5) + 4;
    return n > 100000 ? 100000 : (int)n;
}

static void joints_at(const struct ncp_machine_cfg *c, const struct ncp_seg *s, double dist,
                      double j[NCP_AXES])
{
    double pos[NCP_AXES];
    ncp_seg_eval(s, fmin(fmax(dist, 0), s->length), pos, NULL);
    ncp_kins_inverse(&c->kins, s->tool_z, pos, j);
}

static int limited(const struct ncp_machine_cfg *c, int i)
{
    return (c->axis_mask & NCP_AXIS_BIT(i)) && !c->axis[i].wrapped;
}

int ncp_kins_seg_check(const struct ncp_machine_cfg *c, const struct ncp_seg *s,
                       struct ncp_diag *d)
{
    if (!ncp_kins_active(c) || s->kind == NCP_SEG_DWELL)
        return 0;
    int n = samples(s);
    for (int k = 0; k <= n; k++) {
        double j[NCP_AXES];
        joints_at(c, s, s->length * k / n, j);
        for (int i = 0; i < NCP_AXES; i++) {
            const struct ncp_joint_cfg *jc = &c->joint[i];
            if (!limited(c, i))
                continue;
            const char *u = ncp_axis_rotary(i) ? "deg" : "mm";
            if (j[i] < jc->min_limit - 1e-6)
                return -ncp_diag_set(d, NCP_ERR_LIMIT, s->line, 0,
                                     "joint limit: the %c joint would go to %.4f %s, below its "
                                     "MIN_LIMIT %.4f %s (%s kinematics)",
                                     NCP_AXIS_LETTERS[i], j[i], u, jc->min_limit, u,
                                     ncp_kins_name(c->kins.type));
            if (j[i] > jc->max_limit + 1e-6)
                return -ncp_diag_set(d, NCP_ERR_LIMIT, s->line, 0,
                                     "joint limit: the %c joint would go to %.4f %s, above its "
                                     "MAX_LIMIT %.4f %s (%s kinematics)",
                                     NCP_AXIS_LETTERS[i], j[i], u, jc->max_limit, u,
                                     ncp_kins_name(c->kins.type));
        }
    }
    return 0;
}

/* Fine interpolation keeps 3/5 of every acceleration limit (planner.c). */
static double acc_of(const struct ncp_machine_cfg *c, int i)
{
    return c->joint[i].max_acc * (ncp_machine_cfg_ipo_ratio(c) > 1 ? 0.6 : 1.0);
}

void ncp_kins_seg_caps(const struct ncp_machine_cfg *c, const struct ncp_seg *s, double *vmax,
                       double *acc)
{
    if (!ncp_kins_active(c) || s->kind == NCP_SEG_DWELL || s->length <= 0)
        return;
    int n = samples(s);
    double h = fmax(1e-4 * s->length / n, 1e-7);
    for (int k = 0; k <= n; k++) {
        double at = s->length * k / n;
        at = fmin(fmax(at, h), s->length - h);   /* both neighbours on the segment */
        double jm[NCP_AXES], j0[NCP_AXES], jp[NCP_AXES];
        joints_at(c, s, at - h, jm);
        joints_at(c, s, at, j0);
        joints_at(c, s, at + h, jp);
        for (int i = 0; i < NCP_AXES; i++) {
            if (!(c->axis_mask & NCP_AXIS_BIT(i)))
                continue;
            double d1 = fabs(jp[i] - jm[i]) / (2 * h);
            double d2 = fabs(jp[i] - 2 * j0[i] + jm[i]) / (h * h);
            if (d1 > 1e-12) {
                *vmax = fmin(*vmax, c->joint[i].max_vel / d1);
                *acc = fmin(*acc, 0.5 * acc_of(c, i) / d1);
            }
            if (d2 > 1e-9)
                *vmax = fmin(*vmax, sqrt(0.25 * acc_of(c, i) / d2));
        }
    }
}

double ncp_kins_junction_cap(const struct ncp_machine_cfg *c, const struct ncp_seg *a,
                             const struct ncp_seg *b, double share, double period)
{
    if (!ncp_kins_active(c) || a->kind == NCP_SEG_DWELL || b->kind == NCP_SEG_DWELL ||
        a->length <= 0 || b->length <= 0)
        return INFINITY;
    double ha = fmax(1e-6 * a->length, 1e-7), hb = fmax(1e-6 * b->length, 1e-7);
    double a0[NCP_AXES], a1[NCP_AXES], b0[NCP_AXES], b1[NCP_AXES];
    joints_at(c, a, a->length - ha, a0);
    joints_at(c, a, a->length, a1);
    joints_at(c, b, 0, b0);
    joints_at(c, b, hb, b1);
    double v = INFINITY;
    for (int i = 0; i < NCP_AXES; i++) {
        if (!(c->axis_mask & NCP_AXIS_BIT(i)))
            continue;
        double dj = fabs((b1[i] - b0[i]) / hb - (a1[i] - a0[i]) / ha);
        if (dj > 1e-9)
            v = fmin(v, share * acc_of(c, i) * period / dj);
    }
    return v;
}
