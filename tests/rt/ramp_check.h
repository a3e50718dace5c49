/* Judges the TPDOs of a position ramp by the values they carry, not by when
 * they arrive: a drive in cyclic synchronous position mode answers SYNC j with
 * the target of the RPDO sent just before it, so every actual must be one of
 * the targets the master sent, in the order it sent them. Under software
 * emulation (qemu TCG) answers arrive late in bursts; a strict check also
 * demands they keep up within one period. */
#ifndef NCP_TESTS_RAMP_CHECK_H
#define NCP_TESTS_RAMP_CHECK_H

#include <stdint.h>

struct ncp_ramp_axis {
    int32_t start, step; /* target of cycle j is start + j * step */
    long last_j;         /* cycle of the newest TPDO; -1 before the first */
    long seen;           /* distinct cycles 1..cycles answered */
    long bad;            /* TPDOs with a value never sent, or out of order */
    long max_lag;        /* worst cycles behind at the end of a cycle */
    char why[120];       /* the first bad TPDO, for the message */
};

void ncp_ramp_axis_init(struct ncp_ramp_axis *a, int32_t start, int32_t step);
/* A TPDO with this actual arrived while the newest SYNC sent was that of
 * cycle k (the ramp holds its last target from cycle `cycles` on). */
void ncp_ramp_axis_tpdo(struct ncp_ramp_axis *a, int32_t actual, long k, long cycles);
/* Cycles the axis is behind after cycle k; updates max_lag. */
long ncp_ramp_axis_lag(struct ncp_ramp_axis *a, long k);

#endif
