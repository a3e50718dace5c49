/* Thread creation with the placement of the thread map: policy and priority
 * are set on the attributes before the thread exists, as cyclictest does. */
#include "ncpar/rt.h"

#include <errno.h>
#include <sched.h>

static int create(pthread_t *t, void *(*fn)(void *), void *arg, int priority, int cpu)
{
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    if (priority > 0) {
        struct sched_param sp = { .sched_priority = priority };
        pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
        pthread_attr_setschedparam(&attr, &sp);
    }
    if (cpu >= 0 && cpu < CPU_SETSIZE) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cpu, &set);
        pthread_attr_setaffinity_np(&attr, sizeof set, &set);
    }
    int rc = pthread_create(t, &attr, fn, arg);
    pthread_attr_destroy(&attr);
    return rc;
}

int ncp_rt_spawn(pthread_t *t, void *(*fn)(void *), void *arg, int priority, int cpu,
                 int *fifo)
{
    int rc = create(t, fn, arg, priority, cpu);
    if (fifo)
        *fifo = rc == 0 && priority > 0;
    if (rc == 0 || priority <= 0)
        return rc;
    /* EPERM without CAP_SYS_NICE/rtprio: run anyway, the caller warns */
    return create(t, fn, arg, 0, cpu);
}
