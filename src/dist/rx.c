/* The LLC's receive buffer for period-level setpoints. A setpoint is for a
 * period (t_ns, on the HLC's schedule); the LLC plays period t at a fixed
 * delay after t, so a message that was late on the wire is still on time.
 * Its sequence number tells a loss (a gap) from a duplicate or a stale copy:
 *  - seq above the highest seen: new; the numbers skipped count as lost
 *    (a later arrival of one of them takes it back as reordered);
 *  - its period already held, or seq equal to one held: duplicate;
 *  - its period already played: stale.
 * A period with no setpoint of its own is bridged on the straight line to the
 * next one received, when one is here already; with nothing after it the
 * last one is played again (held): the axis stands rather than guess. */
#include "ncpar/dist.h"

#include <string.h>

void ncp_dist_rx_init(struct ncp_dist_rx *r, int64_t period_ns, int32_t start_nm)
{
    memset(r, 0, sizeof *r);
    r->period_ns = period_ns;
    r->last_nm = start_nm;
}

static unsigned slot_of(const struct ncp_dist_rx *r, int64_t t_ns)
{
    return (unsigned)((uint64_t)(t_ns / r->period_ns) % NCP_DIST_RX_SLOTS);
}

enum ncp_dist_rx_verdict ncp_dist_rx_put(struct ncp_dist_rx *r, int32_t seq, int64_t t_ns,
                                         int32_t nm)
{
    if (t_ns <= 0 || (r->played_t && t_ns <= r->played_t)) {
        r->stale++;
        return NCP_DIST_RX_STALE;
    }
    if (r->played_t && t_ns > r->played_t + (NCP_DIST_RX_SLOTS - 1) * r->period_ns) {
        r->early++;
        return NCP_DIST_RX_EARLY;
    }
    if (!r->have_seq) {
        r->have_seq = 1;
        r->top_seq = seq;
    } else if (seq - r->top_seq > 0) {
        r->lost += (uint32_t)(seq - r->top_seq - 1);
        r->top_seq = seq;
    } else if (seq == r->top_seq) {
        r->duplicate++;
        return NCP_DIST_RX_DUPLICATE;
    } else if (r->lost > 0) {
        /* one that was counted lost came after all, still in time */
        r->lost--;
        r->reordered++;
    }
    /* a second setpoint for a period already held (a copy under a new
     * number, or the sender's clock slipped): the first one stands */
    unsigned k = slot_of(r, t_ns);
    if (r->slot[k].t_ns == t_ns) {
        r->duplicate++;
        return NCP_DIST_RX_DUPLICATE;
    }
    r->slot[k].t_ns = t_ns;
    r->slot[k].nm = nm;
    return NCP_DIST_RX_NEW;
}

/* A period with no setpoint of its own, the last one played before it:
 * with a later one here already it lies on the straight line to it (exact
 * on a line, a chord on an arc), no stop and no double step afterwards (1,
 * *nm set); else 0. */
static int bridge(const struct ncp_dist_rx *r, int64_t t_ns, int32_t *nm)
{
    for (int j = 2; j < NCP_DIST_RX_SLOTS; j++) {
        int64_t tj = t_ns + (j - 1) * r->period_ns;
        unsigned kj = slot_of(r, tj);
        if (r->slot[kj].t_ns == tj) {
            *nm = r->last_nm + (int32_t)(((int64_t)r->slot[kj].nm - r->last_nm) / j);
            return 1;
        }
    }
    return 0;
}

int32_t ncp_dist_rx_play(struct ncp_dist_rx *r, int64_t t_ns)
{
    unsigned k = slot_of(r, t_ns);
    if (r->slot[k].t_ns == t_ns) {
        r->last_nm = r->slot[k].nm;
        r->primed = 1;
    } else if (r->primed) {
        if (bridge(r, t_ns, &r->last_nm))
            r->bridged++;
        else
            r->held++;
    }
    r->played_t = t_ns;
    return r->last_nm;
}

int ncp_dist_rx_level(const struct ncp_dist_rx *r, int64_t t_ns)
{
    int n = 0;
    for (int i = 0; i < NCP_DIST_RX_SLOTS; i++)
        n += r->slot[i].t_ns > t_ns;
    return n;
}

int ncp_dist_rx_peek(const struct ncp_dist_rx *r, int64_t t_ns, int32_t *nm)
{
    unsigned k = slot_of(r, t_ns);
    if (r->slot[k].t_ns == t_ns) {
        *nm = r->slot[k].nm;
        return 1;
    }
    return r->primed && t_ns == r->played_t + r->period_ns && bridge(r, t_ns, nm) ? 2 : 0;
}
