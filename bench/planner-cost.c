/* planner-cost [SEGMENTS]: the motion planner's CPU cost per segment, for
 * bench/bench-motion (default 100000). The look-ahead (ncp_planner_push) and the
 * interpolator (ncp_planner_step, one call per servo period) are driven directly,
 * in one thread, over the segments of bench-motion's program: 0.05 mm chords of
 * 50 mm-radius circles at 100 mm/s, G64 P0.01, the default machine config.
 * Built by `make` with the other bench programs. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "ncpar/motion.h"
static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 100000;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    double r = 50, dphi = 2 * asin(0.05 / (2 * r)), start[NCP_AXES] = { r, 0, 0 };
    struct ncp_planner *p = ncp_planner_new(&cfg, start);
    double t_push = 0, t_step = 0, prev[NCP_AXES] = { r, 0, 0 };
    long k = 1, steps = 0;
    struct ncp_setpoint sp;
    for (;;) {
        double t0 = cpu_s();
        while (k <= n && !ncp_planner_full(p)) {
            struct ncp_seg s = { 0 };
            s.kind = NCP_SEG_LINE;
            s.term = NCP_TERM_CONTINUOUS;
            s.line = (uint32_t)k + 3;
            s.feed = 100;
            s.tolerance = 0.01;
            for (int j = 0; j < NCP_AXES; j++)
                s.start[j] = prev[j];
            s.end[0] = r * cos(k * dphi);
            s.end[1] = r * sin(k * dphi);
            s.length = hypot(s.end[0] - s.start[0], s.end[1] - s.start[1]);
            for (int j = 0; j < NCP_AXES; j++)
                prev[j] = s.end[j];
            ncp_planner_push(p, &s);
            k++;
        }
        if (k > n)
            ncp_planner_finish(p);
        double t1 = cpu_s();
        int more = ncp_planner_step(p, &sp);
        t_step += cpu_s() - t1;
        t_push += t1 - t0;
        steps++;
        if (!more)
            break;
    }
    struct ncp_planner_stats st;
    ncp_planner_get_stats(p, &st);
    printf("segments %ld, servo cycles %ld (%.3f s machine time)\n", n, steps,
           steps * cfg.servo_period);
    printf("look-ahead (push): %.0f ns per segment, %llu entry speeds revised\n",
           1e9 * t_push / (double)n, (unsigned long long)st.replans);
    printf("interpolator (step): %.0f ns per servo cycle, %.0f ns per segment\n",
           1e9 * t_step / (double)steps, 1e9 * t_step / (double)n);
    printf("planner total: %.0f ns per segment (%.2f us CPU per 1 ms period at this load)\n",
           1e9 * (t_push + t_step) / (double)n, 1e6 * (t_push + t_step) / (double)steps);
    ncp_planner_free(p);
    return 0;
}
