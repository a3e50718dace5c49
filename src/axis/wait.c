/* Before the position loop: the LLC advertises itself and heartbeats until
 * the HLC's first setpoint names the period grid, then its loop starts half a
 * period off that grid. Not real-time: polls every millisecond. */
#include "axis.h"

#include <time.h>

#define ADVERT_PERIOD_NS 200000000LL   /* 5 a second until the HLC starts */

int llc_wait_for_hlc(struct llc *l)
{
    int hlc_seen = 0;
    for (;;) {
        int64_t now = llc_now();
        if (now - l->last_adv_ns >= ADVERT_PERIOD_NS) {
            l->last_adv_ns = now;
            llc_advertise(l);
            llc_publish_status(l, 0);
        }
        llc_heartbeat(l, now);
        int64_t before = l->last_hlc_ns;
        llc_take(l, now);
        hlc_seen |= l->last_hlc_ns != before;
        if (l->end != LLC_END_NONE || l->done_req)
            return 0;
        if (atomic_load(&l->signal)) {
            l->end = LLC_END_SIGNAL;
            return 0;
        }
        if (hlc_seen && now - l->last_hlc_ns > l->hb_timeout_ns) {
            l->end = LLC_END_HLC_SILENT;
            return 0;
        }
        /* the oldest setpoint held names the grid */
        int64_t first = 0;
        for (int i = 0; i < NCP_DIST_RX_SLOTS; i++)
            if (l->rx.slot[i].t_ns && (!first || l->rx.slot[i].t_ns < first))
                first = l->rx.slot[i].t_ns;
        if (first) {
            l->t_first = first;
            return 1;
        }
        struct timespec ts = { 0, 1000000 };
        nanosleep(&ts, NULL);
    }
}
