/* The lcm backend's sender at a block-level point (ADCBI DP4): records the
 * planner thread taps, numbered, sent in bursts, kept for resends. */
#ifndef NCP_BACKEND_LCM_TX_H
#define NCP_BACKEND_LCM_TX_H

#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/rt.h"

#define LCM_TX_HIST 4096   /* records kept for a resend: more than an LLC holds */

struct lcm_tx {
    struct ncp_spsc tapped;        /* planner thread -> position loop */
    ncp_accdec_rec_t *hist;        /* LCM_TX_HIST records by number */
    int32_t next, sent;            /* records numbered, records sent */
    int64_t oldest_wait;           /* periods the oldest unsent one has waited */
    int64_t t_start;               /* the period motion last left a standstill (0: never) */
    int32_t starts;                /* how many times it did */
    int32_t burst_seq, mark_seq;
    int sync_left;                 /* syncs still to send at once after the start */
    int64_t last_sync;
    uint64_t bursts, resent, overflow;
    int burst_bytes;
    ncp_accdec_burst_t burst;
    uint8_t buf[8192];
};

int lcm_tx_init(struct lcm_tx *x);
void lcm_tx_free(struct lcm_tx *x);
/* Planner thread: a segment the planner starts. */
void lcm_tx_push(struct lcm_tx *x, const struct ncp_accdec *rec);
/* Position loop, once a period: t the period, moving whether the path left
 * a standstill this period,
 * taken the fewest records any LLC has taken (flow control). */
void lcm_tx_cycle(struct lcm_tx *x, struct ncp_msg *m, int64_t t, int64_t period, int moving,
                  int32_t taken);
/* An LLC's resend request (rec_mark_t) for records from its number on. */
void lcm_tx_resend(struct lcm_tx *x, struct ncp_msg *m, const uint8_t *b, size_t len);

#endif
