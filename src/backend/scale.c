/* The socketcan pieces that need no bus: position scaling between mm and a
 * drive's counts, and the configuration check. */
#include "ncpar/backend.h"

#include <math.h>

int ncp_mm_to_counts(double mm, double counts_per_mm, int32_t *counts)
{
    double c = nearbyint(mm * counts_per_mm);
    if (!(c >= (double)INT32_MIN && c <= (double)INT32_MAX))
        return -1;
    *counts = (int32_t)c;
    return 0;
}

double ncp_counts_to_mm(int32_t counts, double counts_per_mm)
{
    return (double)counts / counts_per_mm;
}

int ncp_socketcan_check_cfg(const struct ncp_machine_cfg *cfg, struct ncp_diag *d)
{
    if (!cfg->can.interface[0])
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "socketcan backend: no CAN interface ([CAN] INTERFACE or "
                            "--backend socketcan:IFACE)");
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        const struct ncp_axis_cfg *a = &cfg->axis[j];
        char ax = NCP_AXIS_LETTERS[j];
        int32_t c;
        if (a->node_id < 1 || a->node_id > 127)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "socketcan backend: [AXIS_%c] NODE_ID missing (the CANopen "
                                "node 1..127 of its drive)",
                                ax);
        if (!(a->counts_per_mm > 0))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "socketcan backend: [AXIS_%c] COUNTS_PER_MM missing", ax);
        if (ncp_mm_to_counts(a->min_limit, a->counts_per_mm, &c) ||
            ncp_mm_to_counts(a->max_limit, a->counts_per_mm, &c))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "socketcan backend: [AXIS_%c] MIN_LIMIT..MAX_LIMIT times "
                                "COUNTS_PER_MM %g does not fit the drive's 32-bit position",
                                ax, a->counts_per_mm);
    }
    return NCP_OK;
}
