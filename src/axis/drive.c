/* The servo an LLC drives: the sim backend's plant of its axis, or one CiA 402
 * drive over SocketCAN (cnc-axis --backend socketcan[:IFACE]), mastered by the
 * socketcan backend with only this axis configured, so that each LLC is the
 * CANopen master of its own drive, as on a machine whose axes sit on
 * separate buses or hosts.
 *
 * The drive is started (SDO, NMT, the CiA 402 walk) before the HLC is
 * waited for; from then on the master keeps SYNC, RPDO and its heartbeat
 * going on its own until the position loop takes over, since an enabled
 * drive guards its master. The loop then gives it one cycle per wake-up:
 * periods the loop slept through are computed (the interpolators must not
 * fall behind) but only the latest goes to the drive, which runs real time
 * and cannot be given periods that already passed. */
#include "axis.h"

#include <string.h>

int llc_drive_open(struct llc *l, const char *spec)
{
    static const double origin[NCP_AXES];
    ncp_sim_init(&l->sim, l->cfg, origin);
    l->drive_cfg = *l->cfg;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int bad = ncp_backend_spec(spec, &l->drive_cfg, &d);
    if (bad > 0)
        return fprintf(stderr, "cnc-axis: --backend is sim or socketcan[:IFACE], not '%s'\n",
                       spec), -1;
    if (bad < 0)
        return fprintf(stderr, "cnc-axis: %s\n", d.msg), -1;
    if (l->drive_cfg.backend == NCP_BACKEND_SIM)
        return 0;
    char ax = NCP_AXIS_LETTERS[l->axis];
    /* this axis's drive only: the others are other LLCs' */
    l->drive_cfg.axis_mask = NCP_AXIS_BIT(l->axis);
    if (ncp_backend_open(&l->drive, &l->drive_cfg, stderr, &d) != NCP_OK)
        return fprintf(stderr, "cnc-axis %c: error: %s\n", ax, d.msg), -1;
    l->has_drive = 1;
    double pos[NCP_AXES] = { 0 };
    if (l->drive.ops->start(&l->drive, pos) != 0) {
        /* said to the HLC as this axis's fault (llc.c waiting()), which
         * names the axis and the cause instead of an axis that never came */
        char why[NCP_DIAG_MSG_MAX];
        l->drive.ops->describe_fault(&l->drive, why, sizeof why);
        l->drive_failed = 1;
        l->end = LLC_END_DRIVE;
        snprintf(l->fault, sizeof l->fault, "drive start-up failed, nothing moved: %s", why);
        llc_fault_short(l->fault_short, sizeof l->fault_short, why);
        return 0;
    }
    /* the axis is where its drive stands: the HLC starts the program there */
    l->cmd = l->cmd_prev = l->act = pos[l->axis];
    fprintf(stderr, "cnc-axis %c: CiA 402 drive node %d on %s enabled at %.4f mm\n", ax,
            l->cfg->axis[l->axis].node_id, l->drive_cfg.can.interface, l->act);
    return 0;
}

void llc_drive_live(struct llc *l)
{
    if (l->has_drive && l->drive.ops->live)
        l->drive.ops->live(&l->drive);
}

/* A fault of the drive (EMCY, heartbeat, state) ends the run: the status
 * says it to the HLC, which stops the other axes. */
static void drive_fault(struct llc *l)
{
    if (l->drive_failed)
        return;
    l->drive_failed = 1;
    char why[NCP_DIAG_MSG_MAX];
    l->drive.ops->describe_fault(&l->drive, why, sizeof why);
    snprintf(l->fault, sizeof l->fault, "drive fault: %s", why);
    llc_fault_short(l->fault_short, sizeof l->fault_short, why);
    if (l->end == LLC_END_NONE || l->end == LLC_END_DONE)
        l->end = LLC_END_DRIVE;
}

void llc_servo(struct llc *l, double cmd, double next, int now)
{
    double c[NCP_AXES] = { 0 }, x[NCP_AXES] = { 0 }, a[NCP_AXES] = { 0 };
    c[l->axis] = cmd;
    x[l->axis] = next;
    if (!l->has_drive) {
        ncp_sim_step(&l->sim, c, x, a);
        l->act = a[l->axis];
    } else if (now && !l->drive_failed) {
        /* the actual position is the TPDO of the last SYNC: a period old */
        a[l->axis] = l->act;
        if (l->drive.ops->cycle(&l->drive, c, x, a) != 0)
            drive_fault(l);
        l->act = a[l->axis];
    }
    l->ferr = l->cmd - l->act;
}

void llc_drive_close(struct llc *l)
{
    if (!l->has_drive)
        return;
    l->drive.ops->stop(&l->drive);
    l->drive.ops->close(&l->drive);
    l->has_drive = 0;
}
