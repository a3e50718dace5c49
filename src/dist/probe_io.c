/* The clock probes' own socket and thread, the same on both sides (the HLC
 * answers, each LLC asks): see ncpar/dist.h. */
#include "ncpar/clock.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <stdint.h>
#include <time.h>

int ncp_dist_probe_io_open(struct ncp_dist_probe_io *io, const struct ncp_lcm_cfg *l,
                           const char *lcm_url, uint64_t seed, struct ncp_diag *d)
{
    io->msg = NULL;
    io->started = 0;
    atomic_store(&io->run, 0);
    char url[128];
    struct ncp_dist_msg_opts o;
    int rc = ncp_dist_clock_url(lcm_url, url, sizeof url, d);
    if (rc == NCP_OK)
        rc = ncp_dist_msg_opts(l, &o, d);
    if (rc == NCP_OK) {
        o.opts.url = url;
        o.opts.prefix = NULL;
        rc = ncp_msg_open(&io->msg, &o.opts, d);
    }
    if (rc != NCP_OK)
        return rc;
    /* probes are lost as anything else is ([LCM] INJECT_LOSS); a delay
     * held back would only wait for the thread's next wake-up, so none */
    struct ncp_msg_inject in = { l->inject_loss, 0, seed };
    if (ncp_msg_set_inject(io->msg, &in) != 0) {
        ncp_dist_probe_io_close(io);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the clock probes");
    }
    return NCP_OK;
}

int ncp_dist_probe_io_run(struct ncp_dist_probe_io *io, void *(*body)(void *), void *arg,
                          struct ncp_diag *d)
{
    atomic_store(&io->run, 1);
    if (pthread_create(&io->thread, NULL, body, arg) != 0) {
        atomic_store(&io->run, 0);
        ncp_dist_probe_io_close(io);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the clock probes' thread");
    }
    io->started = 1;
    return NCP_OK;
}

void ncp_dist_probe_io_close(struct ncp_dist_probe_io *io)
{
    if (io->started) {
        atomic_store(&io->run, 0);
        pthread_join(io->thread, NULL);
        io->started = 0;
    }
    if (io->msg)
        ncp_msg_close(io->msg);
    io->msg = NULL;
}

/* The two clocks cannot be read at once: a preemption between the reads
 * would put its whole length into the offset (milliseconds on a loaded
 * host, where PTP asks for microseconds). The realtime read is bracketed by
 * two monotonic ones and set against their middle; of a few tries the one
 * with the narrowest bracket stands. */
#define OFFSET_TRIES 5
int64_t ncp_dist_realtime_offset(void)
{
    int64_t best = 0, best_gap = INT64_MAX;
    for (int i = 0; i < OFFSET_TRIES; i++) {
        struct timespec r;
        int64_t a = ncp_mono_ns();
        clock_gettime(CLOCK_REALTIME, &r);
        int64_t b = ncp_mono_ns();
        if (b - a < best_gap) {
            best_gap = b - a;
            best = (int64_t)r.tv_sec * 1000000000LL + r.tv_nsec - (a + (b - a) / 2);
        }
    }
    return best;
}
