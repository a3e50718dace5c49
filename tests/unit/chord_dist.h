/* Distance of a point from a chord (the segment a-b) and from a chain of
 * them, for the tests that hold every servo sample to a chain of
 * programmed lines within P. */
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

/* Distance from p to the polyline pts[0..chords] near chord *i: the chords
 * from back before it to ahead after it, so that a path passing near
 * itself is measured in its order; *i moves to the nearest. */
static inline double chain_dist(const double (*pts)[3], int chords, const double p[3], int *i,
                                int back, int ahead)
{
    double best = INFINITY;
    int at = *i;
    for (int k = *i > back ? *i - back : 0; k < chords && k < *i + ahead; k++) {
        double e = chord_dist(p, pts[k], pts[k + 1]);
        if (e < best) {
            best = e;
            at = k;
        }
    }
    *i = at;
    return best;
}

#endif
