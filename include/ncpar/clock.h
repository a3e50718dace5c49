/* The one monotonic clock of ncpar: CLOCK_MONOTONIC as nanoseconds (or
 * milliseconds) since an unspecified start, for timeouts, periods and
 * statistics. Every module reads the time through here, so "now" means the
 * same everywhere and a unit mistake has one place to live.
 *
 * Context: any thread, real-time path included (clock_gettime through the
 * vDSO: no allocation, no blocking, no system call on x86-64 and arm64).
 * Header-only, so cnc-drive-sim, which links only libncpar-can.a, reads
 * the same clock. */
#ifndef NCPAR_CLOCK_H
#define NCPAR_CLOCK_H

#include <stdint.h>
#include <time.h>

static inline int64_t ncp_mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* Whole milliseconds, rounded down (the CAN master's and the panel's
 * timeouts count in them). */
static inline int64_t ncp_mono_ms(void)
{
    return ncp_mono_ns() / 1000000;
}

#endif
