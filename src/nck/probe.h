/* The probe: the position loop arms it, watches it, and brakes on a trip. */
#ifndef NCPAR_NCK_PROBE_H
#define NCPAR_NCK_PROBE_H

#include "ncpar/backend.h"

struct nck_core;

/* The probe (probe.c): the position loop writes it; the job thread reads
 * the result once the probe move's stop was reached (ends_taken). */
enum nck_probe_state { NCK_PROBE_OFF, NCK_PROBE_ARMED, NCK_PROBE_STOPPING, NCK_PROBE_DROPPING };
enum nck_probe_error { NCK_PROBE_OK, NCK_PROBE_TRIPPED_AT_START, NCK_PROBE_NOT_TRIPPED_AT_START };
struct nck_probe {
    int state, flags;
    double last[NCP_AXES];     /* the previous period's actual position */
    uint64_t ends_at_trip;
    int tripped, error;
    double trip[NCP_AXES];     /* machine coordinates */
    double rest[NCP_AXES];     /* where the axes stopped after a trip */
};

/* probe.c (real-time path) */
void nck_probe_arm(struct nck_core *n, int flags);
void nck_probe_cycle(struct nck_core *n, const double act[NCP_AXES]);
int nck_probe_braking(const struct nck_core *n);

#endif
