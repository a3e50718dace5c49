/* Distance of a point from a chord (the segment a-b), for the tests that
 * hold every servo sample to a chain of programmed lines within P. */
#ifndef NCP_TEST_CHORD_DIST_H
#define NCP_TEST_CHORD_DIST_H

#include <math.h>

static inline double chord_dist(const double p[3], const double a[3], const double b[3])
{
    double d[3], q2 = 0, t = 0, e2 = 0;
    for (int j = 0; j < 3; j++) {
        d[j] = b[j] - a[j];
        q2 += d[j] * d[j];
        t += (p[j] - a[j]) * d[j];
    }
    t = q2 > 0 ? fmin(1, fmax(0, t / q2)) : 0;
    for (int j = 0; j < 3; j++)
        e2 += (a[j] + t * d[j] - p[j]) * (a[j] + t * d[j] - p[j]);
    return sqrt(e2);
}

#endif
