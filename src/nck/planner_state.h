/* The planner thread's own state: the source of setpoints. core.c makes and
 * frees it around the thread's life; batch.c reads its statistics after the
 * join (nck_plan_stats). */
#ifndef NCPAR_NCK_PLANNER_STATE_H
#define NCPAR_NCK_PLANNER_STATE_H

#include "ncpar/nck.h"

struct nck_planner {
    /* the ADCBI planner, or under [PLANNER] NCK = adcai the ADCAI chain
     * (the other is NULL) */
    struct ncp_planner *planner;
    struct ncp_adcai *adcai;
    /* starts from rest (wall clock, either clock): when the first segment
     * reached this thread, whether its first setpoint and first moving
     * setpoint are out yet, and the worst of each so far (nck_planner_starts) */
    int64_t start_arrived_ns;
    int start_stepped, start_moved;
    uint64_t starts;
    int64_t start_sp_max_ns, start_move_max_ns;
};

#endif
