/* The simulated spindle's speed command, the ground floor of the machine
 * functions: the speed the spindle ramps to (the programmed S under the
 * speed override, capped at the spindle's top speed) and whether it is
 * there. The position loop's machine step (aux.c) ramps towards it and
 * spindle-synchronised motion (sync.c) waits for it; this file calls
 * neither of them.
 * Real-time rules: no allocation, locks or system calls here. */
#include "nck_int.h"
#include "loop_state.h"

#include <math.h>

double nck_spindle_target(const struct nck_core *n)
{
    const struct nck_mach *m = &n->loop->mach;
    double ov = m->en[NCK_EN_SPEED_OVERRIDE]
                    ? atomic_load_explicit(&n->ctl->spindle_permille, memory_order_relaxed) / 1000.0
                    : 1.0;
    double t = m->rpm_cmd * ov, cap = n->cfg->io.spindle_max_rpm;
    if (cap > 0 && fabs(t) > cap)
        t = copysign(cap, t);
    return t;
}

int nck_spindle_at_speed(const struct nck_core *n)
{
    double t = nck_spindle_target(n);
    return fabs(n->loop->mach.rpm - t) <= fmax(1e-6, n->cfg->io.at_speed_tol * fabs(t));
}
