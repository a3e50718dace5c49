/* G38.x on the position loop: the simulated probe touches the workpiece of
 * [SIM] PROBE_BOX / PROBE_PLANE_Z. An aux action riding on the probe move
 * arms it; each period the actual position is checked, the trip point is
 * found within the period by bisection between the last two actual
 * positions, the stream is slowed to a stop along the path (within the
 * axes' deceleration) and what the planner still has of the move is dropped
 * up to its stop, which then counts as reached. The job thread reads the
 * result once the move's stop is reached (queue buster, job.c).
 * No allocation, locks or system calls: real-time path. */
#include "nck_int.h"
#include "loop_state.h"

#include <string.h>

static int in_contact(const struct ncp_io_cfg *io, const double p[NCP_AXES])
{
    if (io->have_probe_plane && p[2] <= io->probe_plane_z)
        return 1;
    if (!io->have_probe_box)
        return 0;
    for (int k = 0; k < 3; k++)
        if (p[k] < io->probe_box[k] || p[k] > io->probe_box[k + 3])
            return 0;
    return 1;
}

/* The point between a (contact == !want) and b (contact == want) where the
 * contact changes, to far below a micrometre. */
static void crossing(const struct ncp_io_cfg *io, const double a[NCP_AXES],
                     const double b[NCP_AXES], int want, double out[NCP_AXES])
{
    double lo = 0, hi = 1, p[NCP_AXES];
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi);
        for (int k = 0; k < NCP_AXES; k++)
            p[k] = a[k] + mid * (b[k] - a[k]);
        if (in_contact(io, p) == want)
            hi = mid;
        else
            lo = mid;
    }
    for (int k = 0; k < NCP_AXES; k++)
        out[k] = a[k] + hi * (b[k] - a[k]);
}

void nck_probe_arm(struct nck_core *n, int flags)
{
    struct nck_probe *p = &n->loop->probe;
    struct nck_probe_result *r = &n->cross.probe;
    p->flags = flags;
    r->tripped = 0;
    r->error = NCK_PROBE_OK;
    memcpy(r->trip, p->last, sizeof r->trip);
    int contact = in_contact(&n->cfg->io, p->last);
    int away = (flags & NCP_PROBE_F_AWAY) != 0;
    if (contact != away) {
        /* LinuxCNC refuses to start: stop at once, nothing probed */
        r->error = away ? NCK_PROBE_NOT_TRIPPED_AT_START : NCK_PROBE_TRIPPED_AT_START;
        p->state = NCK_PROBE_STOPPING;
        p->ends_at_trip = n->loop->scaler.ends;
        return;
    }
    p->state = NCK_PROBE_ARMED;
}

/* The stop the planner made after the probe move: take it off the stream
 * (the scaler's samples first, then the ring). 1 once found. */
static int drop_to_stop(struct nck_core *n, uint32_t *aux)
{
    struct ncp_scaler *s = &n->loop->scaler;
    if ((s->b.flags & NCP_SP_END) && !s->b_counted) {
        *aux = s->b.aux;
        return 1;
    }
    if (s->have_c && (s->c.flags & NCP_SP_END)) {
        *aux = s->c.aux;
        return 1;
    }
    s->have_c = 0;
    struct ncp_setpoint sp;
    while (ncp_spsc_pop(&n->cross.sps, &sp) == 0)
        if (sp.flags & NCP_SP_END) {
            *aux = sp.aux;
            return 1;
        }
    return 0;
}

void nck_probe_cycle(struct nck_core *n, const double act[NCP_AXES])
{
    struct nck_probe *p = &n->loop->probe;
    struct nck_probe_result *r = &n->cross.probe;
    const struct ncp_io_cfg *io = &n->cfg->io;
    if (p->state == NCK_PROBE_ARMED) {
        int want = !(p->flags & NCP_PROBE_F_AWAY);
        if (in_contact(io, act) == want) {
            crossing(io, p->last, act, want, r->trip);
            r->tripped = 1;
            p->state = NCK_PROBE_STOPPING;
            p->ends_at_trip = n->loop->scaler.ends;
        }
    }
    memcpy(p->last, act, sizeof p->last);
    if (p->state == NCK_PROBE_STOPPING && n->loop->scaler.r == 0 && n->loop->cur.v == 0 &&
        n->loop->next.v == 0) {
        /* the move's own stop was reached while braking: nothing to drop */
        p->state = n->loop->scaler.ends != p->ends_at_trip ? NCK_PROBE_OFF : NCK_PROBE_DROPPING;
        memcpy(r->rest, n->loop->cur.pos, sizeof r->rest);
    }
    uint32_t aux = 0;
    if (p->state == NCK_PROBE_DROPPING && drop_to_stop(n, &aux)) {
        ncp_scaler_rebase(&n->loop->scaler, n->loop->cur.pos);
        nck_loop_note_read(n);
        /* the trace keeps the probe's line while the interpreter catches up */
        n->loop->scaler.a.line = n->loop->scaler.b.line = n->loop->cur.line;
        n->loop->next = n->loop->cur;
        n->loop->ends_seen = n->loop->scaler.ends;
        if (aux > n->loop->mach.seq_reached)
            n->loop->mach.seq_reached = aux;
        p->state = NCK_PROBE_OFF;
        atomic_fetch_add_explicit(&n->cross.ends_taken, 1, memory_order_release);
    }
}

int nck_probe_braking(const struct nck_core *n)
{
    return n->loop->probe.state >= NCK_PROBE_STOPPING;
}
