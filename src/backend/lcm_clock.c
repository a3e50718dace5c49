/* Answers the LLCs' clock probes (see lcm_clock.h). */
#include "lcm_clock.h"

#include "ncpar/dist.h"
#include "ncpar/clock.h"

#include <poll.h>
#include <string.h>
#include <time.h>

int64_t lcm_clock_now(const struct lcm_clock *c)
{
    return ncp_mono_ns() + c->off_ns;
}

static void answer(struct lcm_clock *c, const uint8_t *p, size_t len, int64_t t2)
{
    ncp_clock_probe_t q;
    memset(&q, 0, sizeof q);
    if (ncp_clock_probe_t_decode(p, 0, (int)len, &q) != (int)len || q.sender < 1 ||
        q.sender > NCP_AXES || q.peer != 0)
        return;
    ncp_clock_probe_t a = { c->seq++, NCP_DIST_HLC_ID, q.sender, q.probe_seq, q.t1_ns, t2, 0 };
    uint8_t buf[64];
    a.t3_ns = lcm_clock_now(c);
    int n = ncp_clock_probe_t_encode(buf, 0, sizeof buf, &a);
    if (n > 0 && ncp_msg_publish(c->io.msg, NCP_DIST_CH_CLOCK, buf, (size_t)n) == 0)
        atomic_fetch_add(&c->answered, 1);
}

static void *clock_main(void *arg)
{
    struct lcm_clock *c = arg;
    struct pollfd pfd = { .fd = ncp_msg_fd(c->io.msg), .events = POLLIN };
    while (atomic_load(&c->io.run)) {
        if (poll(&pfd, 1, 50) <= 0)
            continue;
        int sub;
        const uint8_t *p;
        size_t len;
        /* stamped as each is read, not on waking: one read after others
         * waited in the queue, which lengthens its round trip (and the LLC
         * then trusts it less); stamped early, the wait would shorten it */
        while (ncp_msg_take(c->io.msg, ncp_mono_ns(), &sub, &p, &len) == 1)
            answer(c, p, len, lcm_clock_now(c));
    }
    return NULL;
}

int lcm_clock_start(struct lcm_clock *c, const struct ncp_machine_cfg *cfg, struct ncp_diag *d)
{
    memset(c, 0, sizeof *c);
    if (cfg->lcm.clock == NCP_LCM_CLOCK_PTP)
        c->off_ns = ncp_dist_realtime_offset();
    int rc = ncp_dist_probe_io_open(&c->io, &cfg->lcm, cfg->lcm.url,
                                    (uint64_t)cfg->lcm.inject_seed + 1000u, d);
    if (rc != NCP_OK)
        return rc;
    for (int j = 0; j < NCP_AXES; j++) {
        char ch[32];
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        ncp_dist_ax_channel(ch, sizeof ch, j, NCP_DIST_AX_CLOCK);
        ncp_msg_subscribe(c->io.msg, ch);
    }
    return ncp_dist_probe_io_run(&c->io, clock_main, c, d);
}

void lcm_clock_stop(struct lcm_clock *c)
{
    ncp_dist_probe_io_close(&c->io);
}
