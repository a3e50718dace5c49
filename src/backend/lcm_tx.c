/* Block-level records to the LLCs (ADCBI DP4 ACCDECbuf, DP3 LAbuf, DP2
 * INTbuf: the kind says which).
 *
 * The planner taps a record when it starts a segment (DP2: when it gets a
 * block, ahead of that). Its samples reach the
 * position loop through the setpoint ring, so once the ring is full (the
 * planner runs ahead of the loop whenever it can) a record is tapped up to
 * [PLANNER] SETPOINT_RING periods before its first sample plays; at the
 * program's start the ring is still filling and the first records go out
 * at once: the LLCs play LLC_BLOCK_PLAY_DELAY periods behind the HLC, time
 * for a lost one to be asked for and resent. Bursts of NCP_DIST_BURST then,
 * or whatever waited HOLD periods: either way a record is there before its
 * first sample is needed, unless the planner ran dry mid-program (then the
 * LLC stops and says which record it missed). */
#include "lcm_tx.h"

#include <stdlib.h>
#include <string.h>

#define TAP_RING 4096
#define HOLD 50          /* periods an unsent record may wait for a full burst */
#define BURSTS_MAX 2     /* per period: bounds the position loop's time here */
#define SYNC_BURST 6     /* syncs sent in a row at the start: one lost is no delay */

int lcm_tx_init(struct lcm_tx *x, const struct lcm_tx_kind *kind)
{
    memset(x, 0, sizeof *x);
    x->kind = kind;
    x->hist = calloc(LCM_TX_HIST, kind->size);
    x->row = calloc(NCP_DIST_BURST, kind->size);
    x->burst = calloc(1, kind->burst_size);
    if (!x->hist || !x->row || !x->burst ||
        ncp_spsc_init(&x->tapped, kind->size, TAP_RING) != 0) {
        lcm_tx_free(x);
        return -1;
    }
    return 0;
}

void lcm_tx_free(struct lcm_tx *x)
{
    free(x->hist);
    free(x->row);
    free(x->burst);
    x->hist = x->row = NULL;
    x->burst = NULL;
    ncp_spsc_destroy(&x->tapped);
}

void lcm_tx_push(struct lcm_tx *x, const void *rec)
{
    if (ncp_spsc_push(&x->tapped, rec) != 0)
        x->overflow++;
}

static unsigned char *slot(const struct lcm_tx *x, int32_t n)
{
    return x->hist + (size_t)((unsigned)n % LCM_TX_HIST) * x->kind->size;
}

const void *lcm_tx_rec(const struct lcm_tx *x, int32_t n)
{
    return slot(x, n);
}

static void send_burst(struct lcm_tx *x, struct ncp_msg *m, int32_t first, int count)
{
    size_t z = x->kind->size;
    for (int i = 0; i < count; i++)
        memcpy(x->row + (size_t)i * z, lcm_tx_rec(x, first + i), z);
    int n = x->kind->encode(x->buf, sizeof x->buf, x->burst, x->burst_seq++, first, count,
                            x->row);
    if (n > 0 && ncp_msg_publish(m, x->kind->channel, x->buf, (size_t)n) == 0) {
        x->bursts++;
        x->burst_bytes = n;
    }
}

static void sync(struct lcm_tx *x, struct ncp_msg *m)
{
    ncp_rec_mark_t k = { x->mark_seq++, NCP_DIST_HLC_ID, x->t_start, x->sent, x->starts - 1 };
    uint8_t buf[64];
    int n = ncp_rec_mark_t_encode(buf, 0, sizeof buf, &k);
    if (n > 0)
        (void)ncp_msg_publish(m, NCP_DIST_CH_SYNC, buf, (size_t)n);
}

void lcm_tx_cycle(struct lcm_tx *x, struct ncp_msg *m, int64_t t, int64_t period, int moving,
                  int32_t taken, int at_rest)
{
    /* no further than the history can serve resends from */
    while (x->next - taken < LCM_TX_HIST - NCP_DIST_BURST &&
           ncp_spsc_pop(&x->tapped, slot(x, x->next)) == 0)
        x->next++;
    if (x->sent < x->next)
        x->oldest_wait++;
    for (int k = 0; k < BURSTS_MAX && x->sent < x->next; k++) {
        int count = x->next - x->sent;
        if (count > NCP_DIST_BURST)
            count = NCP_DIST_BURST;
        /* flow control: no LLC is sent more than it has room for */
        if (x->sent + count - taken > NCP_DIST_RECS)
            break;
        /* at a standstill a waiting record is the next motion's: a serving
         * NCK's MDI or jog is planned just before the loop runs it */
        if (count < NCP_DIST_BURST && x->t_start && x->oldest_wait < HOLD && !at_rest)
            break;
        send_burst(x, m, x->sent, count);
        x->sent += count;
        x->oldest_wait = 0;
    }
    if (moving) {
        x->t_start = t;
        x->starts++;
        x->sync_left = SYNC_BURST;
    }
    if (x->sync_left > 0 || t - x->last_sync >= 20 * period) {
        if (x->sync_left > 0)
            x->sync_left--;
        x->last_sync = t;
        sync(x, m);
    }
}

void lcm_tx_resend(struct lcm_tx *x, struct ncp_msg *m, const uint8_t *b, size_t len)
{
    ncp_rec_mark_t k;
    memset(&k, 0, sizeof k);
    if (ncp_rec_mark_t_decode(b, 0, (int)len, &k) != (int)len)
        return;
    int32_t from = k.records;
    if (from < 0 || from >= x->sent || x->next - from > LCM_TX_HIST)
        return;
    int count = x->sent - from < NCP_DIST_BURST ? x->sent - from : NCP_DIST_BURST;
    send_burst(x, m, from, count);
    x->resent++;
}

int32_t lcm_tx_void(struct lcm_tx *x)
{
    /* popped into the place of the next number, which stays unnumbered */
    while (ncp_spsc_pop(&x->tapped, slot(x, x->next)) == 0)
        ;
    return x->next;
}
