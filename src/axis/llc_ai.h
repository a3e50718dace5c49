/* The LLC at ADCAI's DP2 and DP3, shared by its two halves: the records
 * through this axis's stages into samples numbered by the HLC's stream
 * index (llc_adcai.c), and those samples played at the HLC's read position
 * (llc_ai_play.c). */
#ifndef NCP_AXIS_LLC_AI_H
#define NCP_AXIS_LLC_AI_H

#include "ncpar/adcai.h"

#include <stdint.h>

/* Samples kept, a power of two: more than the HLC sends ahead of its read
 * (lcm_ai.c's LEAD) plus a record and the play delay behind it. */
#define LLC_AI_SAMPLES 1024
#define LLC_AI_JOBS 4   /* jobs (the HLC's aborts) told apart at once */
#define LLC_AI_MARKS 16 /* the HLC's words on its read kept: more than a play delay's */

struct llc_ai_job {
    int32_t job;
    int64_t k, t;      /* its first sample, the HLC's period of its abort */
    int32_t base_nm;   /* where it starts on this axis */
    int known;
};

struct llc_ai {
    int dp;                         /* 1, 2 or 3 once begun, else 0 */
    int ratio;
    int scurve;                     /* the HLC's loop reads between samples on a quintic */
    struct ncp_adcai_accdec *acc;   /* DP2 */
    struct ncp_adcai_fine *fine;
    int started;
    /* the stages: the job they run, the record expected next, this axis's
     * input summed so far and their output since the job's start (nm) */
    int32_t job;
    int32_t next_seq;
    int32_t in_sum;
    int64_t out_nm;
    /* records the stages remember (ACC/DEC's windows, fine's record and
     * averages), and how many more they will until a bridged one is out of
     * them: till then their state is a guess, not the HLC's chain's */
    int acc_memory, fine_memory;
    int guess_left;
    int64_t top_k;                  /* one past the last sample made */
    int64_t smp_k[LLC_AI_SAMPLES];
    int32_t smp_job[LLC_AI_SAMPLES];
    int32_t smp_nm[LLC_AI_SAMPLES];   /* relative to its job's start */
    struct llc_ai_job jobs[LLC_AI_JOBS];
    /* the HLC's last words on its read (ai_scale_t), by period */
    struct llc_ai_mark {
        int64_t t;          /* its period (0: none) */
        int64_t k;          /* the read position after it */
        double f;
        int32_t job;
        int64_t job_t;      /* the period its job started in */
        double adv[4];      /* the advances up to it, oldest first */
    } marks[LLC_AI_MARKS];
    int have_marks;
    /* the play: the job, the read position of the last slot played */
    int playing;
    int32_t play_job;
    int64_t play_k;
    double play_f;
    int stalled;                    /* the last slot played: the HLC's stream stopped dead */
    uint32_t records, lost, stale, scales, jobs_played;
};

/* llc_adcai.c: the job's facts, NULL when no ai_scale_t said them yet. */
const struct llc_ai_job *llc_ai_job(const struct llc_ai *a, int32_t job);

#endif
