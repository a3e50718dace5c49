/* Thread creation with the placement set on the attributes before the thread
 * exists, as cyclictest does: one spawner for every thread of ncpar. */
#include "ncpar/rt.h"

#include <errno.h>
#include <sched.h>

/* The cpu itself if this process may run there, otherwise the (cpu mod count)-th
 * allowed one: a map written for a bigger machine still pins its threads. */
static int usable_cpu(int cpu, uint32_t *warnings)
{
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0)
        return -1;
    if (cpu < CPU_SETSIZE && CPU_ISSET(cpu, &allowed))
        return cpu;
    int count = CPU_COUNT(&allowed);
    if (count == 0)
        return -1;
    *warnings |= NCP_RT_WARN_NO_CPU;
    int want = cpu % count;
    for (int c = 0; c < CPU_SETSIZE; c++)
        if (CPU_ISSET(c, &allowed) && want-- == 0)
            return c;
    return -1;
}

static int build_attr(pthread_attr_t *a, const struct ncp_rt_place *spec, int fifo,
                      uint32_t *warnings)
{
    int rc = pthread_attr_init(a);
    if (rc != 0)
        return rc;
    if (spec->cpu >= 0) {
        int cpu = usable_cpu(spec->cpu, warnings);
        if (cpu >= 0) {
            cpu_set_t set;
            CPU_ZERO(&set);
            CPU_SET(cpu, &set);
            rc = pthread_attr_setaffinity_np(a, sizeof set, &set);
        }
    }
    if (rc == 0 && fifo) {
        struct sched_param sp = { .sched_priority = spec->priority };
        rc = pthread_attr_setinheritsched(a, PTHREAD_EXPLICIT_SCHED);
        if (rc == 0)
            rc = pthread_attr_setschedpolicy(a, SCHED_FIFO);
        if (rc == 0)
            rc = pthread_attr_setschedparam(a, &sp);
    }
    if (rc != 0)
        pthread_attr_destroy(a);
    return rc;
}

int ncp_rt_start(pthread_t *t, const struct ncp_rt_place *spec, void *(*fn)(void *), void *arg,
                 uint32_t *warnings)
{
    uint32_t ignored = 0;
    if (!warnings)
        warnings = &ignored;
    int fifo = spec->policy == SCHED_FIFO && spec->priority > 0;
    for (;;) {
        pthread_attr_t a;
        int rc = build_attr(&a, spec, fifo, warnings);
        if (rc != 0)
            return rc;
        rc = pthread_create(t, &a, fn, arg);
        pthread_attr_destroy(&a);
        if (rc == EPERM && fifo) {
            *warnings |= NCP_RT_WARN_NO_FIFO;
            fifo = 0;
            continue;
        }
        return rc;
    }
}
