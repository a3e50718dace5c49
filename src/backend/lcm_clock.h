/* The HLC's side of the common time base: a thread of its own answers the
 * LLCs' clock probes (clock_probe_t) as soon as they arrive, on a socket of
 * its own. Answering from the position loop would stamp a probe when the
 * loop next wakes, up to a period after it came, and that wait would count
 * as clock offset; this thread blocks in poll() and stamps on waking. */
#ifndef NCP_BACKEND_LCM_CLOCK_H
#define NCP_BACKEND_LCM_CLOCK_H

#include <stdatomic.h>
#include <stdint.h>

#include "ncpar/config.h"
#include "ncpar/diag.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

struct lcm_clock {
    struct ncp_dist_probe_io io;
    /* the HLC's clock minus its CLOCK_MONOTONIC: CLOCK = ptp stamps
     * CLOCK_REALTIME (which phc2sys keeps on the grandmaster's time), the
     * others CLOCK_MONOTONIC (0) */
    int64_t off_ns;
    int32_t seq;
    atomic_ullong answered;
};

/* The HLC's clock now: CLOCK_MONOTONIC plus off_ns. */
int64_t lcm_clock_now(const struct lcm_clock *c);
/* Opens the socket, subscribes to every axis's probes and starts the
 * thread: NCP_OK, or an error in d. */
int lcm_clock_start(struct lcm_clock *c, const struct ncp_machine_cfg *cfg, struct ncp_diag *d);
void lcm_clock_stop(struct lcm_clock *c);

#endif
