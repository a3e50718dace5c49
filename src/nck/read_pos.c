/* The position loop's read of its setpoint stream, as the backend is told
 * it (backend.h's adv and read_k): noted by the loop where its scaler steps,
 * and by homing, probing and an abort where they rebase the scaler, so that
 * none of them calls the loop for it. */
#include "nck_int.h"
#include "loop_state.h"

#include <stdatomic.h>

/* Where the scaler read the stream for next (backend.h's read_k): the
 * samples it holds are a, b and, fetched ahead, c, each popped in turn from
 * the ring whose head counts them all. */
void nck_loop_note_read(struct nck_core *n)
{
    int64_t head = (int64_t)atomic_load_explicit(&n->cross.sps.head, memory_order_relaxed);
    n->loop->read_k_next = head - (n->loop->scaler.have_c ? 3 : 2);
    n->loop->read_f_next = n->loop->scaler.f;
}

/* next becomes this cycle's command: its read goes to the backend. */
void nck_loop_take_read(struct nck_core *n)
{
    n->cross.be.adv = n->loop->adv_next;
    n->cross.be.read_k = n->loop->read_k_next;
    n->cross.be.read_f = n->loop->read_f_next;
    n->loop->adv_next = 0;
}
