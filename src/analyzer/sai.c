/* rs274's canon keeps its own copy of the program position (moved by motion
 * calls and by SET_G5X_OFFSET / SET_G92_OFFSET / USE_LENGTH_UNITS, never by
 * tool length offsets), and rs274 reloads its current point from that copy at
 * the block after a tool change. We mirror it so that block matches. */
#include "state.h"

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

/* The block after M6/M61 starts from the canon's position. */
void ncp_sai_resync(struct ncp_analyzer *a)
{
    if (!a->st.toolchange_flag)
        return;
    a->st.toolchange_flag = 0;
    memcpy(a->st.pos, a->sai.pos, sizeof a->sai.pos);
    ncp_offsets_sync_params(a); /* before this block's expressions read #5420.. */
    ncp_tools_sync_params(a, 1);
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
        ncp_sai_move(a, op->d);
        break;
    case NCP_C_ARC_FEED:
        a->sai.pos[axes[pl][0]] = op->d[0];
        a->sai.pos[axes[pl][1]] = op->d[1];
        a->sai.pos[axes[pl][2]] = op->d[4];
        memcpy(a->sai.pos + NCP_A, op->d + 5, 3 * sizeof(double));
        break;
    case NCP_C_ARC_REQUEST:
        a->sai.pos[axes[pl][0]] = op->d[2];
        a->sai.pos[axes[pl][1]] = op->d[3];
        a->sai.pos[axes[pl][2]] = op->d[4];
        memcpy(a->sai.pos + NCP_A, op->d + 5, 3 * sizeof(double));
        break;
    default:
        break;
    }
}
