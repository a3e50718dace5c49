/* printf-identical number text. The fast path works on the exact binary value
 * in integer arithmetic, so it decides every rounding exactly as printf does;
 * only magnitudes beyond its integer reach, NaN and inf go to snprintf. */
#include "fmt_num.h"
#include "ncpar/executor.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char ncp_digit_pairs[201] =
    "00010203040506070809" "10111213141516171819" "20212223242526272829"
    "30313233343536373839" "40414243444546474849" "50515253545556575859"
    "60616263646566676869" "70717273747576777879" "80818283848586878889"
    "90919293949596979899";

/* Writes the decimal digits of m ending just before `end`; returns the start. */
static char *ncp_utoa32_back(char *end, uint32_t m)
{
    while (m >= 100u) {
        size_t pair = (size_t)(m % 100u) * 2u;
        m /= 100u;
        end -= 2;
        memcpy(end, ncp_digit_pairs + pair, 2);
    }
    if (m >= 10u) {
        end -= 2;
        memcpy(end, ncp_digit_pairs + (size_t)m * 2u, 2);
    } else {
        *--end = (char)('0' + m);
    }
    return end;
}

/* Machining values stay below 2^32, where 32-bit division is much cheaper:
 * only the rest of a larger n takes 64-bit steps. */
static char *ncp_utoa_back(char *end, uint64_t n)
{
    while (n > UINT32_MAX) {
        size_t pair = (size_t)(n % 100u) * 2u;
        n /= 100u;
        end -= 2;
        memcpy(end, ncp_digit_pairs + pair, 2);
    }
    return ncp_utoa32_back(end, (uint32_t)n);
}

static const uint64_t ncp_pow10[20] = {
    1u, 10u, 100u, 1000u, 10000u, 100000u, 1000000u, 10000000u, 100000000u,
    1000000000u, 10000000000u, 100000000000u, 1000000000000u, 10000000000000u,
    100000000000000u, 1000000000000000u, 10000000000000000u,
    100000000000000000u, 1000000000000000000u, 10000000000000000000u,
};

/* Decimal digits of n: log10 estimated from the bit length (1233/4096 ~
 * log10(2)), corrected by one comparison. No loop, no data-dependent branch. */
static unsigned ncp_digit_count(uint64_t n)
{
    uint64_t m = n | 1u; /* 0 has one digit, like 1 */
    unsigned bits = 64u - (unsigned)__builtin_clzll(m);
    unsigned t = (bits * 1233u) >> 12;
    return t + (m >= ncp_pow10[t]);
}

size_t ncp_fmt_int(char *buf, int32_t v)
{
    char tmp[12];
    char *end = tmp + sizeof tmp;
    uint32_t mag = v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
    char *p = ncp_utoa32_back(end, mag);
    if (v < 0)
        *--p = '-';
    size_t len = (size_t)(end - p);
    memcpy(buf, p, len);
    buf[len] = '\0';
    return len;
}

static size_t ncp_fmt_slow(char *buf, const char *fmt, double v)
{
    int n = snprintf(buf, NCP_FMT_NUM_MAX, fmt, v);
    return n < 0 ? 0 : (size_t)n;
}

/* Fast path limit: 2^46 (~7e13) keeps the integer part well inside 64 bits. */
#define NCP_FMT_FAST_EXP_MAX (1023 + 46)
/* Below 2^-27 a value prints as (-)0.0000 whatever its bits. */
#define NCP_FMT_ZERO_SHIFT 80

/* sign, integer part, '.', four decimals, NUL: digits go straight to their
 * final place, no scratch copy. */
static size_t ncp_put_fixed4(char *buf, int neg, uint64_t ipart, unsigned dec)
{
    size_t len = (size_t)neg + ncp_digit_count(ipart) + 5;
    char *end = buf + len;
    *end = '\0';
    memcpy(end - 4, ncp_digit_pairs + (size_t)(dec / 100u) * 2u, 2);
    memcpy(end - 2, ncp_digit_pairs + (size_t)(dec % 100u) * 2u, 2);
    end[-5] = '.';
    ncp_utoa_back(end - 5, ipart);
    if (neg)
        buf[0] = '-';
    return len;
}

/* The double's exact value is mant * 2^-shift. Splitting it into integer and
 * fraction bits and scaling the fraction by 10^4 in 128-bit integers gives the
 * exact decimal digits and the exact remainder, so the rounding decision is
 * printf's own: up above one half, half-to-even on an exact tie. Kept out of
 * line: the common case below then needs no registers saved. */
static __attribute__((noinline)) size_t ncp_fmt_fixed4_exact(char *buf, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    int neg = (int)(bits >> 63);
    int bexp = (int)((bits >> 52) & 0x7ffu);
    if (bexp >= NCP_FMT_FAST_EXP_MAX)
        return ncp_fmt_slow(buf, "%.4f", v); /* huge, inf, NaN */
    uint64_t ipart = 0;
    unsigned dec = 0;
    int shift = 1075 - bexp; /* > 0 here */
    if (bexp != 0 && shift < NCP_FMT_ZERO_SHIFT) {
        typedef unsigned __int128 u128;
        uint64_t mant = (bits & ((UINT64_C(1) << 52) - 1u)) | (UINT64_C(1) << 52);
        u128 one = (u128)1 << shift;
        u128 frac = (u128)mant & (one - 1u);
        ipart = shift < 64 ? mant >> shift : 0;
        u128 prod = frac * 10000u;
        dec = (unsigned)(prod >> shift);
        u128 rem = prod & (one - 1u);
        u128 half = one >> 1;
        if ((rem > half || (rem == half && (dec & 1u))) && ++dec == 10000u) {
            dec = 0;
            ipart++;
        }
    }
    return ncp_put_fixed4(buf, neg, ipart, dec);
}

/* Below 1e8 the product |v| * 10^4 is within 1.2e-4 of its exact value (half
 * an ulp of a number below 2^40), so when its fraction is more than 1e-3 away
 * from one half, rounding the double product rounds the exact one the same
 * way (zeros and values too small to print included). Near-ties, the values
 * printf must settle half-to-even, and what is not below 1e8 (NaN too) are
 * decided exactly. */
size_t ncp_fmt_fixed4(char *buf, double v)
{
    double a = fabs(v);
    if (a < 1e8) {
        double t = a * 10000.0;
        uint64_t q = (uint64_t)t;
        double f = t - (double)q; /* exact: t < 2^40 */
        if (f > 0.501 || f < 0.499) {
            q += f > 0.501;
            return ncp_put_fixed4(buf, signbit(v) != 0, q / 10000u, (unsigned)(q % 10000u));
        }
    }
    return ncp_fmt_fixed4_exact(buf, v);
}

size_t ncp_fmt_fixed6(char *buf, double v)
{
    return ncp_fmt_slow(buf, "%f", v);
}
