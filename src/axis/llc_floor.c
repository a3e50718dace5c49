/* The LLC's ground floor: its clock, a fault's text cut to a status's
 * field, the period a standstill ended. The position loop (llc.c) and the
 * stages it calls (clock.c, dp1.c, dp1_ai.c, drive.c) stand on it; it calls
 * none of them. */
#include "axis.h"
#include "ncpar/clock.h"

#include <stdio.h>
#include <string.h>

int64_t llc_now(void)
{
    return ncp_mono_ns();
}

void llc_fault_short(char *dst, size_t n, const char *src)
{
    /* cut at a word, not inside a number the HLC would then show */
    if (snprintf(dst, n, "%s", src) >= (int)n) {
        char *cut = dst + n - 4;
        while (cut > dst && *cut != ' ')
            cut--;
        memcpy(cut, "...", 4);
    }
}

int64_t llc_start_at(const struct llc *l, int32_t k)
{
    unsigned i = (unsigned)k % LLC_STARTS;
    return l->start_k[i] == k ? l->start_t[i] : 0;
}
