/* Thin futex wrappers on 32-bit atomics (module-internal header). Process-private
 * waits only: every waiter and waker is a thread of this process. */
#ifndef NCP_PIPELINE_FUTEX_H
#define NCP_PIPELINE_FUTEX_H

#include <limits.h>
#include <linux/futex.h>
#include <stdatomic.h>
#include <stdint.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

/* Sleep while *word == expect (or until timeout, NULL = none). Spurious returns
 * are normal: callers re-check their condition. */
static inline void ncp_futex_wait(_Atomic uint32_t *word, uint32_t expect,
                                  const struct timespec *timeout)
{
    syscall(SYS_futex, (uint32_t *)word, FUTEX_WAIT_PRIVATE, expect, timeout, NULL, 0);
}

static inline void ncp_futex_wake_all(_Atomic uint32_t *word)
{
    syscall(SYS_futex, (uint32_t *)word, FUTEX_WAKE_PRIVATE, INT_MAX, NULL, NULL, 0);
}

static inline void ncp_cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

#endif
