/* rs274's canon keeps its own copy of the program position (moved by motion
 * calls and by SET_G5X_OFFSET / SET_G92_OFFSET / USE_LENGTH_UNITS, never by
 * tool length offsets, backed off after a probe), and rs274 reloads its
 * current point from that copy at the block after a tool change or a probe.
 * We mirror it so that block matches (offsets.c reads it back). */
#include "stages.h"

#include <math.h>
#include <string.h>

void ncp_sai_move(struct ncp_analyzer *a, const double *end)
{
    memcpy(a->sai.pos, end, sizeof a->sai.pos);
}

void ncp_sai_g5x(struct ncp_analyzer *a, const double *v)
{
    for (int k = 0; k < 6; k++) {
        a->sai.pos[k] += a->sai.g5x[k] - v[k];
        a->sai.g5x[k] = v[k];
    }
}

void ncp_sai_g92(struct ncp_analyzer *a, const double *v)
{
    for (int k = 0; k < 6; k++) {
        a->sai.pos[k] += a->sai.g92[k] - v[k];
        a->sai.g92[k] = v[k];
    }
}

void ncp_sai_units(struct ncp_analyzer *a, int inches)
{
    if (inches == a->sai.inches)
        return;
    for (int k = 0; k < 3; k++) {
        if (inches) {
            a->sai.pos[k] /= NCP_MM_PER_INCH;
            a->sai.g5x[k] /= NCP_MM_PER_INCH;
            a->sai.g92[k] /= NCP_MM_PER_INCH;
        } else {
            a->sai.pos[k] *= NCP_MM_PER_INCH;
            a->sai.g5x[k] *= NCP_MM_PER_INCH;
            a->sai.g92[k] *= NCP_MM_PER_INCH;
        }
    }
    a->sai.inches = inches;
}

/* rs274 -g's STRAIGHT_PROBE: the probe trips at the programmed end, and the
 * canon backs its position off 0.254 mm (0.01 in) from there towards where
 * it was in X, Y and Z (not at all when those three did not move); A, B and
 * C end at the end. */
void ncp_sai_probe(struct ncp_analyzer *a, const double *end)
{
    double *pos = a->sai.pos;
    double dx = pos[NCP_X] - end[NCP_X], dy = pos[NCP_Y] - end[NCP_Y],
           dz = pos[NCP_Z] - end[NCP_Z];
    double distance = sqrt(dx * dx + dy * dy + dz * dz);
    memcpy(a->sai.probed, end, sizeof a->sai.probed);
    for (int ax = NCP_A; ax <= NCP_C; ax++)
        pos[ax] = end[ax];
    if (distance != 0) {
        double backoff = a->sai.inches ? 0.01 : 0.254;
        pos[NCP_X] = end[NCP_X] + backoff * (dx / distance);
        pos[NCP_Y] = end[NCP_Y] + backoff * (dy / distance);
        pos[NCP_Z] = end[NCP_Z] + backoff * (dz / distance);
    }
    a->sai.probe_flag = 1;
}

/* A move finished by the comp queue: the canon's point is its end. */
void ncp_sai_op(struct ncp_analyzer *a, const struct ncp_canon *op)
{
    static const int axes[3][3] = {{NCP_X, NCP_Y, NCP_Z}, {NCP_Y, NCP_Z, NCP_X},
                                   {NCP_Z, NCP_X, NCP_Y}};
    int pl = a->st.m.plane;
    switch (op->kind) {
    case NCP_C_STRAIGHT_TRAVERSE:
    case NCP_C_STRAIGHT_FEED:
        ncp_sai_move(a, op->move.end);
        break;
    case NCP_C_ARC_FEED:
        a->sai.pos[axes[pl][0]] = op->arc_feed.first_end;
        a->sai.pos[axes[pl][1]] = op->arc_feed.second_end;
        a->sai.pos[axes[pl][2]] = op->arc_feed.axis_end;
        memcpy(a->sai.pos + NCP_A, op->arc_feed.abc, 3 * sizeof(double));
        break;
    case NCP_C_ARC_REQUEST:
        a->sai.pos[axes[pl][0]] = op->arc.first_end;
        a->sai.pos[axes[pl][1]] = op->arc.second_end;
        a->sai.pos[axes[pl][2]] = op->arc.axis_end;
        memcpy(a->sai.pos + NCP_A, op->arc.abc, 3 * sizeof(double));
        break;
    default:
        break;
    }
}
