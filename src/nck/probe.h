/* The probe: the position loop arms it, watches it, and brakes on a trip. */
#ifndef NCPAR_NCK_PROBE_H
#define NCPAR_NCK_PROBE_H

#include "ncpar/backend.h"

struct nck_core;

/* The probe (probe.c): the position loop arms and watches it; the job
 * thread reads the result once the probe move's stop was reached. */
enum nck_probe_state { NCK_PROBE_OFF, NCK_PROBE_ARMED, NCK_PROBE_STOPPING, NCK_PROBE_DROPPING };
enum nck_probe_error { NCK_PROBE_OK, NCK_PROBE_TRIPPED_AT_START, NCK_PROBE_NOT_TRIPPED_AT_START };
/* The loop's own (loop_state.h). */
struct nck_probe {
    int state, flags;
    double last[NCP_AXES];     /* the previous period's actual position */
    uint64_t ends_at_trip;
};
/* The result (crossing.h): the loop writes it before the probe move's stop
 * counts in ends_taken; the job reads it after. */
struct nck_probe_result {
    int tripped, error;
    double trip[NCP_AXES];     /* machine coordinates */
    double rest[NCP_AXES];     /* where the axes stopped after a trip */
};

/* probe.c (real-time path) */
void nck_probe_arm(struct nck_core *n, int flags);
void nck_probe_cycle(struct nck_core *n, const double act[NCP_AXES]);
int nck_probe_braking(const struct nck_core *n);

#endif
