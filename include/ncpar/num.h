/* Strict numbers for command-line options and configuration values: the
 * whole string is the number (no blank before it, nothing after it), it is
 * finite and it lies in [lo, hi]. Each returns 0 and sets *out, or returns -1
 * and leaves *out alone. One parser, so "--lexers 3x", " 3" and "1e999" are
 * refused the same way by every tool and every INI key.
 *
 * ncp_num_why writes the message a caller prints when it has none of its own:
 * "WHAT is a number from LO to HI, not 'S'", the name of what was parsed and
 * its range in it.
 *
 * Context: any thread outside the real-time path (strtod may read the
 * locale). Header-only: cnc-drive-sim links only libncpar-can.a. */
#ifndef NCPAR_NUM_H
#define NCPAR_NUM_H

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static inline int ncp_num_double(const char *s, double lo, double hi, double *out)
{
    char *end;
    if (!s || !*s || isspace((unsigned char)*s))
        return -1;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || *end || !isfinite(v) || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

/* base as strtol's: 10 for counts and indices; 0 lets an object index be
 * written 0x6060 as CiA 402 names it. */
static inline int ncp_num_long(const char *s, int base, long lo, long hi, long *out)
{
    char *end;
    if (!s || !*s || isspace((unsigned char)*s))
        return -1;
    errno = 0;
    long v = strtol(s, &end, base);
    if (errno || *end || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static inline int ncp_num_int(const char *s, int lo, int hi, int *out)
{
    long v;
    if (ncp_num_long(s, 10, lo, hi, &v))
        return -1;
    *out = (int)v;
    return 0;
}

static inline void ncp_num_why(char *why, size_t len, const char *what, const char *s, double lo,
                               double hi)
{
    snprintf(why, len, "%s is a number from %g to %g, not '%s'", what, lo, hi, s ? s : "");
}

#endif
