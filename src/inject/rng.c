/* xoshiro256** seeded through splitmix64 (Vigna's constants): fast, good
 * enough for fault statistics, and the same sequence on every host, which
 * rand() does not promise. */
#include "ncpar/inject.h"

#include <math.h>

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void ncp_xoshiro_seed(struct ncp_xoshiro *r, uint64_t seed)
{
    uint64_t x = seed;
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix64(&x);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

uint64_t ncp_xoshiro_next(struct ncp_xoshiro *r)
{
    uint64_t *s = r->s;
    uint64_t out = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return out;
}

double ncp_xoshiro_uniform(struct ncp_xoshiro *r)
{
    return (double)(ncp_xoshiro_next(r) >> 11) * 0x1.0p-53;
}

/* Box-Muller with one of the pair: two draws per value keeps the stream's
 * use per period fixed, which keeps the other periods' draws in place. */
double ncp_xoshiro_normal(struct ncp_xoshiro *r)
{
    double u1 = 1.0 - ncp_xoshiro_uniform(r);   /* (0, 1]: log stays finite */
    double u2 = ncp_xoshiro_uniform(r);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}
