/* ADCAI's DP2 and DP3 messages. Encoding through the generated code; the
 * LLC decodes by hand, as fine_ipo_t, because the generated decoder
 * allocates its variable array. The layouts differ only in DP2's flag. */
#include "ncpar/dist.h"

#include <string.h>

static int64_t rough_hash, accdec_hash;

void ncp_dist_ai_init(void)
{
    rough_hash = __ncp_rough_ipo_t_get_hash();
    accdec_hash = __ncp_accdec_ai_t_get_hash();
}

int ncp_dist_encode_ai(uint8_t *buf, size_t size, int dp, const struct ncp_dist_ai *r)
{
    if (r->n < 0 || r->n > NCP_AXES || size > 0x7fffffff || (dp != 2 && dp != 3))
        return -1;
    int32_t sum[NCP_AXES];
    memcpy(sum, r->sum_nm, sizeof sum);
    if (dp == 2) {
        ncp_rough_ipo_t m = { r->seq, r->sender, r->k, r->job, r->flag, r->n, sum };
        return ncp_rough_ipo_t_encode(buf, 0, (int)size, &m);
    }
    ncp_accdec_ai_t m = { r->seq, r->sender, r->k, r->job, r->n, sum };
    return ncp_accdec_ai_t_encode(buf, 0, (int)size, &m);
}

static uint64_t be(const uint8_t *p, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v = v << 8 | p[i];
    return v;
}

/* fingerprint 8, seq 4, sender 2, k 8, job 4, [flag 1,] n 1, then n times 4 */
int ncp_dist_decode_ai(const uint8_t *buf, size_t len, int dp, struct ncp_dist_ai *r)
{
    size_t fixed = dp == 2 ? 28 : 27;
    if ((dp != 2 && dp != 3) || len < fixed ||
        (int64_t)be(buf, 8) != (dp == 2 ? rough_hash : accdec_hash))
        return -1;
    int n = buf[fixed - 1];   /* an int8: above 127 it is negative, refused as too many */
    if (n > NCP_AXES || len != fixed + 4u * (size_t)n)
        return -1;
    r->seq = (int32_t)(uint32_t)be(buf + 8, 4);
    r->sender = (int16_t)(uint16_t)be(buf + 12, 2);
    r->k = (int64_t)be(buf + 14, 8);
    r->job = (int32_t)(uint32_t)be(buf + 22, 4);
    r->flag = dp == 2 ? (int8_t)buf[26] : 0;
    r->n = (int8_t)n;
    for (int i = 0; i < n; i++)
        r->sum_nm[i] = (int32_t)(uint32_t)be(buf + fixed + (size_t)4 * (size_t)i, 4);
    return 0;
}
