/* The ACC/DEC's window lengths from the machine's limits. On its own so that
 * the INI reader can check them without the filters. */
#include "ncpar/adcai.h"

#include <math.h>

/* The first filter's output changes its velocity by at most dv over n1
 * periods, dv = 2 V: the input may go from +V to -V (a reversal, which no
 * look-ahead slows for). Its acceleration is then at most 2V / (n1 T); the
 * second filter bounds the jerk the same way by 2 A1 / (n2 T). Quantising
 * positions to 1 nm adds up to 2 nm / T^2 to an acceleration and 4 nm / T^3
 * to a jerk: the windows keep 2 % of each limit for it. */
int ncp_adcai_windows(const struct ncp_machine_cfg *cfg, double period, int n[2])
{
    double n1 = 1, n2 = 1;
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        const struct ncp_axis_cfg *a = &cfg->axis[j];
        n1 = fmax(n1, ceil(2 * a->max_vel / (0.98 * a->max_acc * period) - 1e-9));
    }
    for (int j = 0; cfg->profile == NCP_PROFILE_SCURVE && j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)) || !(cfg->axis[j].max_jerk > 0))
            continue;
        const struct ncp_axis_cfg *a = &cfg->axis[j];
        double a1 = 2 * a->max_vel / (n1 * period);
        n2 = fmax(n2, ceil(2 * a1 / (0.98 * a->max_jerk * period) - 1e-9));
    }
    if (!(n1 <= NCP_ADCAI_WINDOW_MAX) || !(n2 <= NCP_ADCAI_WINDOW_MAX))
        return -1;
    n[0] = (int)n1;
    n[1] = (int)n2;
    return 0;
}
