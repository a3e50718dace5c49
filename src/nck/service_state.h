/* The caller's thread's own part of the core (the service thread, or the
 * batch run's caller): the threads it started, and what it made of the
 * cycles the loop handed it. */
#ifndef NCPAR_NCK_SERVICE_STATE_H
#define NCPAR_NCK_SERVICE_STATE_H

#include "cycle.h"

#include <pthread.h>

struct nck_service {
    int be_open, be_started;
    pthread_t planner_thread;
    int planner_started, loop_started;
    struct nck_summary sum;
    struct nck_fb last_fb;
    int have_fb;
    uint64_t pauses;                 /* operator waits begun */
};

#endif
