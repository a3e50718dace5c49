/* Starting pipeline threads with a thread map's placement (module-internal). */
#ifndef NCP_PIPELINE_THREADS_H
#define NCP_PIPELINE_THREADS_H

#include <pthread.h>
#include <stdint.h>
#include "ncpar/pipeline.h"

/* Start fn(arg) with spec's policy/priority, and its cpu when pin is set.
 * SCHED_FIFO refused (EPERM) falls back to SCHED_OTHER and a cpu this process
 * may not use to another one it may; both add a NCP_WARN_* bit to *warnings.
 * Returns 0 or the pthread_create error. */
int ncp_thread_start(pthread_t *t, const struct ncp_thread_spec *spec, int pin,
                     void *(*fn)(void *), void *arg, uint32_t *warnings);

#endif
