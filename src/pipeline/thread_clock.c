/* The clocks the pipeline's statistics read: its wall clock and the calling
 * thread's CPU and kernel time. Apart from the stages, which read them at
 * each thread's end, so that a serial run reads the same ones at its own. */
#include "pipe.h"

#include "ncpar/clock.h"

#include <sys/resource.h>
#include <time.h>

double ncp_pipe_now_ms(void)
{
    return (double)ncp_mono_ns() / 1e6;
}

double ncp_pipe_thread_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

double ncp_pipe_thread_sys_ms(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_THREAD, &ru) != 0)
        return 0;
    return (double)ru.ru_stime.tv_sec * 1e3 + (double)ru.ru_stime.tv_usec / 1e3;
}
