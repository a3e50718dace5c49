/* The lcm backend's sender at a block-level point (ADCBI DP2, DP3, DP4):
 * records the planner thread hands over, numbered, sent in bursts, kept for
 * resends. What a record is and how a burst of them is encoded is the
 * point's (struct lcm_tx_kind, lcm_kinds.c); the numbering, flow control and
 * resends are the same for all. */
#ifndef NCP_BACKEND_LCM_TX_H
#define NCP_BACKEND_LCM_TX_H

#include <stdatomic.h>

#include "ncpar/backend.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/rt.h"

#define LCM_TX_HIST 4096   /* records kept for a resend: more than an LLC holds */

struct lcm_tx_kind {
    int dp;
    const char *channel;
    size_t size;          /* one record as the planner thread hands it over */
    size_t burst_size;    /* the point's LCM burst struct */
    /* recs: count records in a row; burst: burst_size bytes to fill */
    int (*encode)(uint8_t *buf, size_t cap, void *burst, int32_t seq, int32_t first, int count,
                  const void *recs);
};
extern const struct lcm_tx_kind lcm_kind_accdec, lcm_kind_la, lcm_kind_int;

struct lcm_tx {
    const struct lcm_tx_kind *kind;
    struct ncp_spsc tapped;        /* planner thread -> position loop */
    unsigned char *hist;           /* LCM_TX_HIST records by number */
    unsigned char *row;            /* a burst's records in a row */
    void *burst;                   /* the LCM struct a burst is encoded from */
    int32_t next, sent;            /* records numbered, records sent */
    int64_t oldest_wait;           /* periods the oldest unsent one has waited */
    int64_t t_start;               /* the period motion last left a standstill (0: never) */
    int32_t starts;                /* how many times it did */
    int32_t burst_seq, mark_seq;
    int sync_left;                 /* syncs still to send at once after the start */
    int64_t last_sync;
    uint64_t bursts, resent, overflow;
    int burst_bytes;
    uint8_t buf[16384];
};

int lcm_tx_init(struct lcm_tx *x, const struct lcm_tx_kind *kind);
void lcm_tx_free(struct lcm_tx *x);
/* Planner thread: a record of the kind's (a segment the planner starts, or
 * at DP2 a call the planner got). */
void lcm_tx_push(struct lcm_tx *x, const void *rec);
/* Record number n, still held (n in [next - LCM_TX_HIST, next)). */
const void *lcm_tx_rec(const struct lcm_tx *x, int32_t n);
/* Position loop, once a period: t the period, moving whether the path left
 * a standstill this period,
 * taken the fewest records any LLC has taken (flow control), at_rest
 * whether the path stands (records waiting then go out at once). */
void lcm_tx_cycle(struct lcm_tx *x, struct ncp_msg *m, int64_t t, int64_t period, int moving,
                  int32_t taken, int at_rest);
/* Position loop, after an abort parked the planner: the records tapped and
 * not numbered yet are dropped; returns the number below which every record
 * is the aborted job's. */
int32_t lcm_tx_void(struct lcm_tx *x);
/* An LLC's resend request (rec_mark_t) for records from its number on. */
void lcm_tx_resend(struct lcm_tx *x, struct ncp_msg *m, const uint8_t *b, size_t len);

/* ---- ADCBI DP1 (lcm_dp1.c): the program to run ------------------------ */
struct lcm_dp1 {
    ncp_program_t msg;
    int32_t seq;
    int bytes;                     /* the message's encoded size */
};
/* Reads c->program for its size and hash: 0, or -1 (errno says why). */
int lcm_dp1_init(struct lcm_dp1 *p, const struct ncp_lcm_cfg *c);
void lcm_dp1_send(struct lcm_dp1 *p, struct ncp_msg *m);

/* ---- ADCBI DP2 (lcm_dp2.c): the planner's calls as INTbuf records ------- */
struct lcm_dp2 {
    int32_t steps_own;             /* planner thread: steps its planner took */
    _Atomic int32_t steps;         /* the same, for the position loop */
    int32_t mark_seq, last_steps;
    int64_t last_mark;
};
/* Planner thread: one call on the planner (plan_journal). */
void lcm_dp2_journal(struct lcm_tx *x, struct lcm_dp2 *d, enum ncp_plan_call c,
                     const struct ncp_seg *s, const double *pos);
/* Position loop, after lcm_tx_cycle: how far the LLCs' planners may step
 * with the records sent so far. steps: d->steps read BEFORE lcm_tx_cycle
 * took the planner thread's records (every call before those steps is
 * then among them). */
void lcm_dp2_mark(const struct lcm_tx *x, struct lcm_dp2 *d, struct ncp_msg *m, int32_t steps,
                  int64_t t, int64_t period);

#endif
