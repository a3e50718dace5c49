/* The common time base of the LLCs and the HLC, as one LLC keeps it
 * (clock.c). */
#ifndef NCP_AXIS_LLC_CLOCK_H
#define NCP_AXIS_LLC_CLOCK_H

#include <stdatomic.h>
#include <stdint.h>

#include "ncpar/config.h"
#include "ncpar/diag.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

/* The common time base (clock.c): written by the probe thread (the window
 * and the estimate's atomics) or by the position loop (applied, slewing). */
struct llc_clock {
    struct ncp_dist_probe_io io;  /* the probe thread and its own socket */
    char channel[32];             /* NCP_AX_<L>_CLOCK */
    enum ncp_lcm_clock mode;
    int64_t tolerance_ns;
    int64_t base_ns;              /* ptp: CLOCK_REALTIME - CLOCK_MONOTONIC at start, else 0 */
    /* cnc-axis --clock-skew-us, --clock-drift-ppm: tests only, another
     * host's clock simulated on this one */
    int64_t skew_ns, mono0;
    double drift_ppm;
    int32_t seq;
    struct ncp_dist_clock win;
    _Atomic int64_t est_offset, est_rtt, est_jitter;
    atomic_int probes;            /* in the estimate's window: 0 none yet */
    atomic_int ready;             /* the estimate stands (see clock.c) */
    atomic_ullong sent, answers;
    int64_t applied;              /* the HLC's clock minus this one, as the grid runs */
    int64_t slewed;               /* all the slewing, ns */
    int slewing;
};

struct llc;
/* clock.c: the common time base */
int llc_clock_start(struct llc *l, const char *url, struct ncp_diag *d);
void llc_clock_stop(struct llc *l);
/* This LLC's clock (mono_ns: CLOCK_MONOTONIC), and the HLC's as it maps. */
int64_t llc_clock_local(const struct llc_clock *c, int64_t mono_ns);
int64_t llc_hlc_time(const struct llc *l, int64_t mono_ns);
/* The estimate stands: a full window of probes, short round trips or many. */
int llc_clock_known(const struct llc *l);
/* Once a period, from the loop: follows the estimate (CLOCK = probe; stepped
 * until grid_known, then slewed) or checks it: 0, or -1 when the clocks are
 * further apart than CLOCK_TOLERANCE_US. */
int llc_clock_cycle(struct llc *l, int grid_known);
void llc_clock_status(const struct llc *l, ncp_ax_status_t *s);
void llc_clock_report(const struct llc *l);

#endif
