/* The lcm backend's sender at ADCAI's DP2 (roughIPObuf) and DP3 (ACCDECbuf):
 * a message every rough period, on the HLC's period grid. */
#ifndef NCP_BACKEND_LCM_AI_H
#define NCP_BACKEND_LCM_AI_H

#include "ncpar/adcai.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/rt.h"

struct lcm_ai {
    int dp, n;
    int axis[NCP_AXES];            /* the machine's axes in the LLCs' order */
    struct ncp_spsc tapped;        /* planner thread -> position loop, a setpoint each */
    struct ncp_adcai_tap front;    /* the oldest not yet played */
    int have_front, last_moved, primed;
    int64_t last_pos[NCP_AXES];
    int32_t seq;
    uint64_t sent, overflow, unmatched;
    int bytes;
};

int lcm_ai_init(struct lcm_ai *x, int dp, const struct ncp_machine_cfg *cfg);
void lcm_ai_free(struct lcm_ai *x);
/* Planner thread: one setpoint's tap. */
void lcm_ai_push(struct lcm_ai *x, const struct ncp_adcai_tap *t);
/* Position loop, once a period: t the period, cmd what the loop plays in it. */
void lcm_ai_cycle(struct lcm_ai *x, struct ncp_msg *m, int64_t t, const double cmd[NCP_AXES]);

/* The summary line (stderr). */
void lcm_ai_report(const struct lcm_ai *x);

#endif
