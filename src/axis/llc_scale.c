/* The HLC's time scaling at ADCBI's block-level points (time_scale_t,
 * NCP_HLC_SCALE): how far its position loop read its setpoint stream in each
 * of its periods. This LLC's interpolator advances by the same amount in the
 * slot of that period, so a feed hold, stop, override or underrun at the HLC
 * slows and stops every axis at the same instants of the program's time: the
 * path stays the program's, and each axis stands where the HLC's command
 * stands. A period the HLC said nothing about keeps the newest advance heard
 * before it (1 until the first message): the HLC repeats each advance that
 * is not 1 in 16 messages and says 1 for 32 periods after the last, so a
 * silent HLC in a feed hold leaves its axes standing, not running on. */
#include "axis.h"

#include <string.h>

static unsigned place(const struct llc *l, int64_t t)
{
    return (unsigned)((uint64_t)(t / l->period_ns) % LLC_SCALE_HIST);
}

void llc_scale_put(struct llc *l, int64_t t_ns, const double *adv, int count)
{
    for (int i = 0; i < count; i++) {
        int64_t t = t_ns - (int64_t)(count - 1 - i) * l->period_ns;
        unsigned k = place(l, t);
        l->scale.t[k] = t;
        l->scale.adv[k] = adv[i];
    }
    if (t_ns > l->scale.newest_t) {
        l->scale.newest_t = t_ns;
        l->scale.newest = adv[count - 1];
    }
}

void llc_on_scale(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_time_scale_t m;
    memset(&m, 0, sizeof m);
    if (ncp_time_scale_t_decode(p, 0, (int)len, &m) != (int)len || m.sender != NCP_DIST_HLC_ID ||
        m.count < 1 || m.count > 16)
        return;
    /* lcm-gen decodes doubles through int64_t pointers: read back as
     * doubles, the compiler (LTO, strict aliasing) took them for the
     * memset's zeros. Bytes copied out are what was decoded. */
    double adv[16];
    memcpy(adv, m.adv, sizeof adv);
    llc_scale_put(l, m.t_ns, adv, m.count);
    /* a new abort by its period: one after homing drops no record (the
     * count stays) but restarts the interpolator with homing's offset */
    if (m.void_t_ns > l->scale.void_t && m.void_below >= l->scale.void_below) {
        l->scale.void_below = m.void_below;
        l->scale.void_t = m.void_t_ns;
        l->scale.void_due = 1;
        l->scale.void_off = ncp_dist_nm_to_mm(m.void_off_nm[l->axis]);
    }
}

double llc_scale_at(const struct llc *l, int64_t slot)
{
    if (!l->scale.newest_t)
        return 1.0;
    unsigned k = place(l, slot);
    if (l->scale.t[k] == slot)
        return l->scale.adv[k];
    /* past the newest word: it holds; before it and not heard: the HLC
     * said nothing then, which it does only at its own pace */
    return slot > l->scale.newest_t ? l->scale.newest : 1.0;
}

int llc_scale_void_waits(const struct llc *l, int64_t slot)
{
    return l->scale.void_due && slot >= l->scale.void_t && l->dp == 2 &&
           l->scale.drops < l->scale.void_below;
}

int llc_scale_void(struct llc *l, int64_t slot)
{
    if (!l->scale.void_due || slot < l->scale.void_t)
        return 0;
    if (llc_scale_void_waits(l, slot)) {
        l->scale.drop_waits++;
        return 1;
    }
    l->scale.void_due = 0;
    /* DP2: the HLC's calls all stay (this planner replays every one, the
     * aborted job's too, to stay the HLC's); what it made before the
     * abort's DROP is what the interpolator drops */
    if (l->dp == 2)
        ncp_dist_recs_skip(&l->own, l->scale.drop_own[(unsigned)l->scale.void_below % LLC_DROPS]);
    else
        ncp_dist_recs_skip(&l->recs, l->scale.void_below);
    l->ex_on = 0;
    l->stop_rested = 0;
    l->catching = 0;   /* the stream it was catching up with is gone */
    l->rec_off = l->scale.void_off;
    l->scale.voided++;
    return 0;
}
