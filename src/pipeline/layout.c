/* The layout `cnc-run parse` runs when no flag names one: threads only where
 * the program is long enough to pay for starting them. */
#include "ncpar/pipeline.h"

#include <sched.h>
#include <stdint.h>
#include <unistd.h>

/* The model behind the threshold (bench/RESULTS.md, "Program size"): a
 * parallel run costs a fixed start (creating the threads, allocating and
 * prefaulting their rings, the first hand-offs while a thread is still being
 * scheduled) and then saves a share of serial's cost per block. It wins once
 *
 *     bytes * serial cost per byte * (1 - 1 / speed-up)  >  start cost,
 *
 * and the threshold sits well above that point, so that a program just past
 * it gains clearly rather than breaking even within the noise.
 * PARALLEL_FROM_BYTES_2CPU is that threshold for a machine with two usable
 * CPUs, in bytes of program text: bench/size-curve measures the break-even
 * point, and bench/RESULTS.md ("Program size") records it with the machine
 * and date the constant was chosen from. */
#define PARALLEL_FROM_BYTES_2CPU ((size_t)8 << 20)

int ncp_cpus_usable(void)
{
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) {
        int n = CPU_COUNT(&allowed);
        if (n > 0)
            return n;
    }
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)(n > CPU_SETSIZE ? CPU_SETSIZE : n) : 1;
}

/* One CPU: the stages would only take turns on it, never win. Two: the
 * measured threshold. More: the default layout starts five stage threads
 * instead of two, so its start cost is taken to grow with their number while
 * its gain per block is taken to be no more than the two-thread layout's,
 * which only widens the margin: not measured here (bench/size-curve on such a
 * machine gives the real point). */
size_t ncp_auto_parallel_bytes(int cpus)
{
    if (cpus < 2)
        return SIZE_MAX;
    if (cpus == 2)
        return PARALLEL_FROM_BYTES_2CPU;
    return PARALLEL_FROM_BYTES_2CPU / 2 * 5;
}

void ncp_thread_map_auto(struct ncp_thread_map *m, size_t bytes, int cpus)
{
    if (bytes < ncp_auto_parallel_bytes(cpus))
        ncp_thread_map_default(m, NCP_MODE_SERIAL, 0, 0);
    else if (cpus <= 2)
        /* two busy threads, the analyzer lexing the text itself and
         * interpreting it, the output thread executing and writing: more
         * stage threads than cores only adds hand-offs, and a lexer thread's
         * blocks cost the analyzer about as much to take over from the other
         * core as to lex them itself */
        ncp_thread_map_default(m, NCP_MODE_DET, 0, 0);
    else
        ncp_thread_map_default(m, NCP_MODE_DET, 2, 1);
}
