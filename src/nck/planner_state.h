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
};

#endif
