/* Channel names and units of the distributed mode. */
#include "ncpar/dist.h"

#include <math.h>
#include <stdio.h>

void ncp_dist_ax_channel(char *buf, size_t size, int axis, enum ncp_dist_ax_ch what)
{
    static const char *const tail[] = { "ADVERT", "STATUS", "HEARTBEAT", "RESEND", "CLOCK" };
    snprintf(buf, size, "NCP_AX_%c_%s", NCP_AXIS_LETTERS[axis], tail[what]);
}

int ncp_dist_mm_to_nm(double mm, int32_t *nm)
{
    double v = nearbyint(mm * 1e6);
    if (!(v >= -2147483648.0 && v <= 2147483647.0))
        return -1;
    *nm = (int32_t)v;
    return 0;
}
