/* The ACC/DEC's window lengths from the machine's limits. On its own so that
 * the INI reader can check them without the filters. */
#include "ncpar/adcai.h"

#include <math.h>

/* The first filter's output changes its velocity by at most dv over n1
 * periods, dv = 2 V: the input may go from +V to -V (a reversal, which no
 * look-ahead slows for). Its acceleration is then at most 2V / (n1 T); the
 * second filter bounds the jerk the same way by 2 A1 / (n2 T). Quantising
 * positions to 1 nm adds up to 2 nm / Ts^2 to an acceleration and 4 nm /
 * Ts^3 to a jerk at the servo period Ts; the position loop's time scaling
 * would take any excess over a limit for the stream's and slow down, so the
 * windows leave that much room, and 2 % more. */
int ncp_adcai_windows(const struct ncp_machine_cfg *cfg, double period, int n[2])
{
    const double q = 1 / NCP_ADCAI_UNITS_PER_MM, ts = cfg->servo_period;
    double n1 = 1, n2 = 1;
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        const struct ncp_axis_cfg *a = &cfg->axis[j];
        double room = 0.98 * a->max_acc - 2 * q / (ts * ts);
        if (!(room > 0))
            return -1;
        n1 = fmax(n1, ceil(2 * a->max_vel / (room * period) - 1e-9));
    }
    for (int j = 0; cfg->profile == NCP_PROFILE_SCURVE && j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)) || !(cfg->axis[j].max_jerk > 0))
            continue;
        const struct ncp_axis_cfg *a = &cfg->axis[j];
        double a1 = 2 * a->max_vel / (n1 * period);
        double room = 0.98 * a->max_jerk - 4 * q / (ts * ts * ts);
        if (!(room > 0))
            return -1;
        n2 = fmax(n2, ceil(2 * a1 / (room * period) - 1e-9));
    }
    if (!(n1 <= NCP_ADCAI_WINDOW_MAX) || !(n2 <= NCP_ADCAI_WINDOW_MAX))
        return -1;
    n[0] = (int)n1;
    n[1] = (int)n2;
    return 0;
}
