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

void llc_end_text(const struct llc *l, char *dst, size_t n)
{
    /* each fits a status's 64 bytes with its numbers whole: the HLC keeps
     * it as the axis's last error, the operator reads it there */
    switch (l->end) {
    case LLC_END_NONE:
    case LLC_END_DONE: snprintf(dst, n, "%s", ""); break;
    case LLC_END_HLC_STOP:
        if (l->hlc_axis)
            snprintf(dst, n, "the HLC ordered a stop (axis %c lost)", l->hlc_axis);
        else
            snprintf(dst, n, "the HLC ordered a stop (its start-up failed)");
        break;
    case LLC_END_HLC_SILENT:
        snprintf(dst, n, "the HLC's heartbeat lost (none for %d ms)",
                 l->cfg->lcm.heartbeat_timeout_ms);
        break;
    case LLC_END_LOST:
        snprintf(dst, n, "over %d setpoints in a row lost (HLC heard %lld ms before)",
                 l->cfg->lcm.max_lost_periods, (long long)((l->lost_at_ns - l->last_hlc_ns) / 1000000));
        break;
    case LLC_END_FERROR:
        /* a host that stalled this loop is said, the numbers kept whole */
        if (l->fault_late_ns)
            snprintf(dst, n, "following error %.4f mm > FERROR %.4f mm: loop %.0f ms late",
                     l->fault_ferr, l->cfg->axis[l->axis].ferror, (double)l->fault_late_ns * 1e-6);
        else
            snprintf(dst, n, "following error %.4f mm exceeds FERROR %.4f mm", l->fault_ferr,
                     l->cfg->axis[l->axis].ferror);
        break;
    case LLC_END_MISSING: snprintf(dst, n, "record %d missing when needed", (int)l->missing_rec); break;
    case LLC_END_SIGNAL: snprintf(dst, n, "stopped by a signal (SIGINT or SIGTERM)"); break;
    case LLC_END_PROGRAM:
    case LLC_END_DRIVE: snprintf(dst, n, "%s", l->fault_short[0] ? l->fault_short : l->fault); break;
    case LLC_END_CLOCK: llc_fault_short(dst, n, l->fault); break;
    }
}
