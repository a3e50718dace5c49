/* fine_ipo_t by hand on the receiving side: the generated decoder allocates
 * its variable array, which the LLC's position loop must not do. Encoding
 * goes through the generated code (it only reads), so both ends stay the
 * type lcm-gen describes; tests/unit/test_dist.c checks the decoder against
 * the generated one. */
#include "ncpar/dist.h"

#include <string.h>

static int64_t fine_hash;

void ncp_dist_init(void)
{
    fine_hash = __ncp_fine_ipo_t_get_hash();
}

int ncp_dist_encode_fine(uint8_t *buf, size_t size, const struct ncp_dist_fine *f)
{
    if (f->n < 0 || f->n > NCP_AXES || size > 0x7fffffff)
        return -1;
    int32_t pos[NCP_AXES];
    memcpy(pos, f->pos_nm, sizeof pos);
    ncp_fine_ipo_t m = { f->seq, f->sender, f->t_ns, f->n, pos };
    return ncp_fine_ipo_t_encode(buf, 0, (int)size, &m);
}

static uint64_t be(const uint8_t *p, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v = v << 8 | p[i];
    return v;
}

/* fingerprint 8, seq 4, sender 2, t_ns 8, n 1, then n times 4 */
#define FIXED 23

int ncp_dist_decode_fine(const uint8_t *buf, size_t len, struct ncp_dist_fine *f)
{
    if (len < FIXED || (int64_t)be(buf, 8) != fine_hash)
        return -1;
    int n = buf[22];   /* an int8: above 127 it is negative, refused as too many */
    if (n > NCP_AXES || len != FIXED + 4u * (size_t)n)
        return -1;
    f->seq = (int32_t)(uint32_t)be(buf + 8, 4);
    f->sender = (int16_t)(uint16_t)be(buf + 12, 2);
    f->t_ns = (int64_t)be(buf + 14, 8);
    f->n = (int8_t)n;
    for (int i = 0; i < n; i++)
        f->pos_nm[i] = (int32_t)(uint32_t)be(buf + FIXED + (size_t)4 * (size_t)i, 4);
    return 0;
}
