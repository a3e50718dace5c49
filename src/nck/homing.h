/* Homing: the request from the caller's thread, the phases on the position loop. */
#ifndef NCPAR_NCK_HOMING_H
#define NCPAR_NCK_HOMING_H

#include "ncpar/backend.h"
#include "ncpar/nck.h"

struct nck_core;

/* Homing (homing.c): the position loop drives each axis of the request on
 * its own, away from the planner, through LinuxCNC's phases; the trace's
 * `home` column shows each axis's phase as one digit. */
enum nck_home_phase { NCK_HP_NONE, NCK_HP_OFF_SWITCH, NCK_HP_SEARCH, NCK_HP_BACK_OFF,
                      NCK_HP_LATCH, NCK_HP_LATCHED, NCK_HP_FINAL,
                      NCK_HP_DRIVE /* HOME_METHOD = drive:N: the drive homes itself */ };
enum nck_home_result { NCK_HOME_OK, NCK_HOME_NOT_FOUND, NCK_HOME_STOPPED, NCK_HOME_NO_DRIVE };
struct nck_home_axis {
    int phase;             /* enum nck_home_phase */
    int queued;            /* waits for its HOME_SEQUENCE's turn */
    int stopping;          /* the phase's event came: braking to a stop */
    int aborted;           /* NCK_HP_DRIVE: the drive was told to stop homing */
    double pos, v;         /* commanded position (machine coordinates), velocity */
    double from;           /* where the phase began: a search's travel is bounded */
};
/* The request and its result (crossing.h): the caller's thread writes mask,
 * then counts req; the loop counts done once that request is over (result,
 * fail_axis, final and latched then hold for the caller). */
struct nck_home_req {
    unsigned mask;
    _Atomic uint32_t req, done;
    int result, fail_axis;
    double final[NCP_AXES];
    double latched[NCP_AXES];  /* where the switch latched, simulated machine's coordinates */
};
/* The run (loop_state.h): the loop's alone. */
struct nck_homing {
    uint32_t taken;
    int active;
    struct nck_home_axis ax[NCP_AXES];
    /* the simulated machine's position minus the machine position: homing
     * sets the machine position where the switch latches */
    double off[NCP_AXES];
};

/* homing.c. The loop: nck_home_take instead of the planned setpoint (1 when
 * homing drives this period), nck_home_sense after the backend's cycle,
 * nck_home_cancel on an E-stop or fault (loop.c's drive() puts home.off
 * between the joints and the backend). The caller's thread: nck_home_request
 * (at rest, nothing queued), nck_home_finished once the loop is done. */
int nck_home_take(struct nck_core *n);
void nck_home_sense(struct nck_core *n, const double act[NCP_AXES]);
void nck_home_cancel(struct nck_core *n);
int nck_home_active(const struct nck_core *n);
uint64_t nck_home_phases(const struct nck_core *n);
/* The order of homing: HOME_SEQUENCE's absolute value; without any
 * HOME_SEQUENCE in the INI, Z first, then all the others together. */
int nck_home_seq(const struct ncp_machine_cfg *c, int axis);
/* The axes "home all" homes: all of them, or, once any axis has a
 * HOME_SEQUENCE, those that have one (LinuxCNC's rule). */
unsigned nck_home_all_mask(const struct ncp_machine_cfg *c);
void nck_home_request(struct nck_core *n, unsigned mask);
int nck_home_finished(const struct nck_core *n);
/* One line per homed axis of the last request (where its switch latched),
 * or why homing failed; 0, or -1 when it failed. */
int nck_home_report(const struct nck_core *n, char *buf, size_t len);

#endif
