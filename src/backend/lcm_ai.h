/* The lcm backend's sender at ADCAI's DP2 (roughIPObuf) and DP3
 * (ACCDECbuf): a record every rough period, placed by the stream index of
 * its first sample, and the position loop's read of the stream (ai_scale_t). */
#ifndef NCP_BACKEND_LCM_AI_H
#define NCP_BACKEND_LCM_AI_H

#include "ncpar/adcai.h"
#include "ncpar/backend.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/rt.h"

#define LCM_AI_WINDOW 4   /* periods each ai_scale_t carries */

struct lcm_ai {
    int dp, n;
    int64_t T;                     /* the servo period, ns */
    int ratio;                     /* servo periods a rough period */
    int axis[NCP_AXES];            /* the machine's axes in the LLCs' order */
    struct ncp_spsc tapped;        /* planner thread -> position loop, a setpoint each */
    struct ncp_adcai_tap front;    /* popped, not yet due to be sent */
    int have_front;
    int64_t k_next;                /* the stream index of the next tap popped */
    int32_t seq;
    /* the job the samples belong to: aborts so far, its first sample, the
     * period of its abort and where its sums start */
    int32_t job;
    int64_t job_k, job_t;
    int32_t base_nm[NCP_AXES];
    int based;
    uint32_t discards_seen;
    double adv[LCM_AI_WINDOW];     /* the last periods' advances, oldest first */
    int left;                      /* periods ai_scale_t is still sent every period */
    int32_t scale_seq;
    int64_t last_scale_t;
    uint64_t sent, overflow, scale_sent, dropped;
    int bytes;
    /* the last record as sent, said again while no later one follows */
    uint8_t last[128];
    int last_len;
    int repeats_left;
    int64_t last_t;
    uint64_t repeated;
};

int lcm_ai_init(struct lcm_ai *x, int dp, const struct ncp_machine_cfg *cfg);
void lcm_ai_free(struct lcm_ai *x);
/* Planner thread: one setpoint's tap. */
void lcm_ai_push(struct lcm_ai *x, const struct ncp_adcai_tap *t);
/* Position loop, once a period: t the period (skipped: periods the loop
 * slept through before it), b the loop's read of its stream, cmd what it
 * plays in it. */
void lcm_ai_cycle(struct lcm_ai *x, struct ncp_msg *m, int64_t t, int64_t skipped,
                  const struct ncp_backend *b, const double cmd[NCP_AXES]);

/* The summary line (stderr). */
void lcm_ai_report(const struct lcm_ai *x);

#endif
