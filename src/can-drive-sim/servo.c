/* The optional servo plant of a simulated drive: one axis of the sim
 * backend's machine (src/backend/sim.c), so that a run over CAN can be
 * compared with a run on the simulated machine. */
#include <stdio.h>

#include "drive.h"

double drive_period_s(struct drive *dv)
{
    double t = od_get(&dv->od, 0x60C2, 1);
    unsigned raw = od_get(&dv->od, 0x60C2, 2) & 0xFFu; /* INTEGER8 */
    for (int e = raw >= 128 ? (int)raw - 256 : (int)raw; e < 0; e++)
        t /= 10;
    return t > 0 ? t : 1e-3;
}

void drive_servo_enable(struct drive *dv)
{
    if (!dv->servo)
        return;
    double start[NCP_AXES] = {0};
    struct ncp_machine_cfg c = dv->cfg;
    c.servo_period = drive_period_s(dv);
    start[dv->o.axis] = ncp_counts_to_mm(dv->actual, c.axis[dv->o.axis].counts_per_mm);
    ncp_sim_init(&dv->sim, &c, start);
    dv->prev_target = dv->actual;
}

/* The sim backend's step: the command of this period is the target that
 * came before the previous SYNC, the new one its feed-forward look-ahead;
 * the answer is the position measured at the SYNC, before the step. */
int32_t drive_servo_step(struct drive *dv)
{
    int j = dv->o.axis;
    double cpm = dv->cfg.axis[j].counts_per_mm;
    double cmd[NCP_AXES], next[NCP_AXES], act[NCP_AXES];
    for (int k = 0; k < NCP_AXES; k++) {
        cmd[k] = ncp_counts_to_mm(dv->prev_target, cpm);
        next[k] = ncp_counts_to_mm(dv->target, cpm);
    }
    ncp_sim_step(&dv->sim, cmd, next, act);
    dv->prev_target = dv->target;
    int32_t counts;
    return ncp_mm_to_counts(act[j], cpm, &counts) ? dv->actual : counts;
}

int drive_servo_load(struct drive *dv)
{
    if (!dv->o.config)
        return 0;
    struct ncp_diag d;
    ncp_machine_cfg_default(&dv->cfg);
    if (ncp_machine_cfg_load(&dv->cfg, dv->o.config, &d) != NCP_OK) {
        fprintf(stderr, "cnc-drive-sim: %s%s\n", d.msg, d.line ? " (line of the INI above)" : "");
        return -1;
    }
    if (dv->o.axis < 0 || !(dv->cfg.axis[dv->o.axis].counts_per_mm > 0)) {
        fprintf(stderr, "cnc-drive-sim: --config needs --axis X|Y|Z with COUNTS_PER_MM set\n");
        return -1;
    }
    dv->servo = 1;
    return 0;
}

