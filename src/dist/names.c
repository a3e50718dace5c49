/* Channel names and units of the distributed mode. */
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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

int ncp_dist_clock_url(const char *url, char *buf, size_t size, struct ncp_diag *d)
{
    if (url == NULL || url[0] == 0) {
        url = getenv("LCM_DEFAULT_URL");
        if (url == NULL || url[0] == 0)
            url = NCP_MSG_DEFAULT_URL;
    }
    struct ncp_msg_url u;
    int rc = ncp_msg_parse_url(url, &u, d);
    if (rc != NCP_OK)
        return rc;
    if (u.port == 65535)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "%s: the clock probes take the next port, and 65535 has none", url);
    snprintf(buf, size, "udpm://%s:%u?ttl=%d", u.group, (unsigned)u.port + 1u, u.ttl);
    return NCP_OK;
}
