/* The records of each block-level point as lcm_tx sends them: what the
 * planner thread hands over and the LCM burst it goes out in. */
#include "lcm_tx.h"

#include <string.h>

#define FILL(b, seq_, first_, count_)                                                        \
    do {                                                                                     \
        memset((b), 0, sizeof *(b));                                                         \
        (b)->seq = (seq_);                                                                   \
        (b)->sender = NCP_DIST_HLC_ID;                                                       \
        (b)->first = (first_);                                                               \
        (b)->count = (int8_t)(count_);                                                       \
    } while (0)

static int enc_accdec(uint8_t *buf, size_t cap, void *burst, int32_t seq, int32_t first,
                      int count, const void *recs)
{
    ncp_accdec_burst_t *b = burst;
    const struct ncp_accdec *r = recs;
    FILL(b, seq, first, count);
    for (int i = 0; i < count; i++)
        ncp_dist_rec_encode(&r[i], &b->recs[i]);
    return ncp_accdec_burst_t_encode(buf, 0, (int)cap, b);
}

static int enc_la(uint8_t *buf, size_t cap, void *burst, int32_t seq, int32_t first, int count,
                  const void *recs)
{
    ncp_la_burst_t *b = burst;
    const struct ncp_la *r = recs;
    FILL(b, seq, first, count);
    for (int i = 0; i < count; i++)
        ncp_dist_la_encode(&r[i], &b->recs[i]);
    return ncp_la_burst_t_encode(buf, 0, (int)cap, b);
}

static int enc_int(uint8_t *buf, size_t cap, void *burst, int32_t seq, int32_t first, int count,
                   const void *recs)
{
    ncp_int_burst_t *b = burst;
    const struct ncp_dist_op *r = recs;
    FILL(b, seq, first, count);
    for (int i = 0; i < count; i++)
        ncp_dist_op_encode(&r[i], &b->recs[i]);
    return ncp_int_burst_t_encode(buf, 0, (int)cap, b);
}

const struct lcm_tx_kind lcm_kind_accdec = { 4, NCP_DIST_CH_ACCDEC, sizeof(struct ncp_accdec),
                                             sizeof(ncp_accdec_burst_t), enc_accdec };
const struct lcm_tx_kind lcm_kind_la = { 3, NCP_DIST_CH_LA, sizeof(struct ncp_la),
                                         sizeof(ncp_la_burst_t), enc_la };
const struct lcm_tx_kind lcm_kind_int = { 2, NCP_DIST_CH_INT, sizeof(struct ncp_dist_op),
                                          sizeof(ncp_int_burst_t), enc_int };
