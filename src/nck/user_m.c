/* M100..M199 on the machine: the executable of that name (ncp_user_m_find,
 * the machine INI's [DISPLAY] PROGRAM_PREFIX and [RS274NGC] USER_M_PATH)
 * runs with P and Q as two arguments formatted as LinuxCNC's task formats
 * them ("%f"), once the motion before it has come to a stop; the program
 * goes on when it exits 0. Runs on the job thread, never on the position
 * loop's: the loop holds the axes where they stopped meanwhile. */
#include "nck_int.h"
#include "job_state.h"

#include "ncpar/analyzer.h"

#include <errno.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>

extern char **environ;

static void nap_ms(long ms)
{
    struct timespec ts = { ms / 1000, (ms % 1000) * 1000000L };
    nanosleep(&ts, NULL);
}

/* The program gets none of this process's signal handling, blocked signals
 * or real-time priority (the job thread may run SCHED_FIFO). posix_spawn
 * does not copy the address space: the locked memory of the position loop
 * is not made copy-on-write for a moment, as fork would make it. */
static int spawn(pid_t *pid, char *const argv[])
{
    posix_spawnattr_t at;
    if (posix_spawnattr_init(&at))
        return ENOMEM;
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    sigdelset(&all, SIGKILL);
    sigdelset(&all, SIGSTOP);
    struct sched_param sp = { .sched_priority = 0 };
    int rc = posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF |
                                               POSIX_SPAWN_SETSCHEDULER);
    if (!rc)
        rc = posix_spawnattr_setsigmask(&at, &none);
    if (!rc)
        rc = posix_spawnattr_setsigdefault(&at, &all);
    if (!rc)
        rc = posix_spawnattr_setschedpolicy(&at, SCHED_OTHER);
    if (!rc)
        rc = posix_spawnattr_setschedparam(&at, &sp);
    if (!rc)
        rc = posix_spawn(pid, argv[0], NULL, &at, argv, environ);
    posix_spawnattr_destroy(&at);
    return rc;
}

/* The job is aborted (stop, E-stop, shutdown), or a batch run was asked
 * to stop (a signal): its loop, frozen at rest on a virtual clock while
 * the program runs, would not get to end the job itself. */
static int aborted(struct nck_core *n)
{
    return atomic_load(&n->job->abort) || (n->batch && atomic_load(&n->ctl->stop));
}

/* Waits for pid; an abort (stop, E-stop) interrupts the program as
 * LinuxCNC's abort does (SIGINT), and kills it when it does not end within
 * a second. 0 with *status, -1 aborted (reaped all the same), or an errno
 * of waitpid (the child lost: someone else reaped it). */
static int wait_child(struct nck_core *n, pid_t pid, int *status)
{
    long since_abort = -1;
    for (;;) {
        pid_t r = waitpid(pid, status, WNOHANG);
        if (r == pid)
            return since_abort >= 0 ? -1 : 0;
        if (r < 0 && errno != EINTR)
            return errno > 0 ? errno : EIO;
        if (since_abort < 0 && aborted(n)) {
            kill(pid, SIGINT);
            since_abort = 0;
        } else if (since_abort >= 0 && (since_abort += 1) == 1000) {
            kill(pid, SIGKILL);
        }
        nap_ms(1);
    }
}

int nck_user_m_run(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op)
{
    struct nck_job *j = n->job;
    int code = op->user_m.code;
    uint16_t col = (uint16_t)op->user_m.col;
    const char *file = NCP_CMD_FILE(cmd) ? ncp_diag_file_of_tag(NCP_CMD_FILE(cmd)) : NULL;
    char path[1600], p[64], q[64];
    if (n->quiet)   /* the estimate: the program's time, not its side effects */
        return 0;
    if (ncp_user_m_find(n->cfg->rs274.user_m_dirs, code, path, sizeof path) != 0) {
        ncp_diag_set(&j->map_diag, NCP_ERR_SEMANTIC, cmd->line, col,
                     "M%d: its program is gone from [RS274NGC] USER_M_PATH (%s) since the "
                     "interpreter started", code, n->cfg->rs274.user_m_dirs);
        j->map_diag.file = file;
        return -1;
    }
    snprintf(p, sizeof p, "%f", op->user_m.p);
    snprintf(q, sizeof q, "%f", op->user_m.q);
    char *argv[] = { path, p, q, NULL };
    if (!n->batch)
        nck_post(n, NCP_EV_INFO, file, cmd->line, col, "M%d: running %s %s %s", code, path, p, q);
    fflush(NULL);
    pid_t pid;
    int err = spawn(&pid, argv);
    if (err) {
        ncp_diag_set(&j->map_diag, NCP_ERR_IO, cmd->line, col, "M%d: cannot run %s: %s", code,
                     path, strerror(err));
        j->map_diag.file = file;
        return -1;
    }
    int st = 0;
    int w = wait_child(n, pid, &st);
    if (w > 0) {
        ncp_diag_set(&j->map_diag, NCP_ERR_IO, cmd->line, col, "M%d: lost %s while it ran: %s",
                     code, path, strerror(w));
        j->map_diag.file = file;
    }
    if (w)
        return -1;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0)
        return 0;
    if (WIFEXITED(st))
        ncp_diag_set(&j->map_diag, NCP_ERR_SEMANTIC, cmd->line, col,
                     "M%d: %s exited with status %d; the program stops here", code, path,
                     WEXITSTATUS(st));
    else
        ncp_diag_set(&j->map_diag, NCP_ERR_SEMANTIC, cmd->line, col,
                     "M%d: %s was ended by signal %d (%s); the program stops here", code, path,
                     WTERMSIG(st), strsignal(WTERMSIG(st)));
    j->map_diag.file = file;
    return -1;
}
