/* The panel's slow queries off the socket thread: a worker thread takes
 * them in order and leaves each answer for the socket thread, which only
 * moves finished messages to their sockets. A preview that takes seconds
 * (or is killed at its limits) thus never delays a command: the socket
 * thread stays free to read an E-stop and hand it on.
 *
 * The worker runs niced below the socket and serving threads (and its
 * child below it). The queues are bounded: a socket that asks faster than
 * the worker answers is refused, never queued without end. */
#include "server_int.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#define JOB_QUEUE 16
#define WORKER_NICE 5

struct job {
    uint64_t serial;
    enum ncp_http_req r;
};

struct done {
    uint64_t serial;
    struct ncp_http_msg msg;
};

struct ncp_http_jobs {
    struct ncp_http_jobs_env env;
    pthread_t thread;
    atomic_int stop;
    pthread_mutex_t mu;         /* guards the two queues */
    pthread_cond_t wake;
    struct job jobs[JOB_QUEUE];
    unsigned job_head, job_n;
    struct done done[JOB_QUEUE];
    unsigned done_head, done_n;
};

static void *worker(void *arg)
{
    struct ncp_http_jobs *j = arg;
    (void)setpriority(PRIO_PROCESS, (id_t)gettid(), WORKER_NICE);
    pthread_mutex_lock(&j->mu);
    for (;;) {
        while (!j->job_n && !atomic_load(&j->stop))
            pthread_cond_wait(&j->wake, &j->mu);
        if (atomic_load(&j->stop))
            break;
        struct job job = j->jobs[j->job_head];
        pthread_mutex_unlock(&j->mu);
        struct ncp_http_prog *prog = j->env.prog_get(j->env.ctx);
        struct ncp_http_msg msg = { NULL, 0 };
        int bad = ncp_http_build_answer(&j->env.paths, prog, job.r, &j->stop, &msg);
        if (prog)
            ncp_http_prog_put(prog);
        pthread_mutex_lock(&j->mu);
        /* the job leaves its queue only now: its slot in the answers is free
         * (both queues together hold at most JOB_QUEUE) */
        j->job_head = (j->job_head + 1) % JOB_QUEUE;
        j->job_n--;
        /* out of memory: an empty answer, so that its socket may ask again */
        j->done[(j->done_head + j->done_n++) % JOB_QUEUE] =
            (struct done){ job.serial, bad ? (struct ncp_http_msg){ NULL, 0 } : msg };
        pthread_mutex_unlock(&j->mu);
        j->env.wake(j->env.ctx);
        pthread_mutex_lock(&j->mu);
    }
    pthread_mutex_unlock(&j->mu);
    return NULL;
}

struct ncp_http_jobs *ncp_http_jobs_start(const struct ncp_http_jobs_env *env)
{
    struct ncp_http_jobs *j = calloc(1, sizeof *j);
    if (!j)
        return NULL;
    j->env = *env;
    pthread_mutex_init(&j->mu, NULL);
    pthread_cond_init(&j->wake, NULL);
    int rc = ncp_http_spawn(&j->thread, worker, j);
    if (rc) {
        pthread_cond_destroy(&j->wake);
        pthread_mutex_destroy(&j->mu);
        free(j);
        return NULL;
    }
    return j;
}

int ncp_http_jobs_submit(struct ncp_http_jobs *j, uint64_t serial, enum ncp_http_req r)
{
    pthread_mutex_lock(&j->mu);
    int full = j->job_n + j->done_n >= JOB_QUEUE;
    if (!full) {
        j->jobs[(j->job_head + j->job_n++) % JOB_QUEUE] = (struct job){ serial, r };
        pthread_cond_signal(&j->wake);
    }
    pthread_mutex_unlock(&j->mu);
    return full ? -1 : 0;
}

int ncp_http_jobs_take(struct ncp_http_jobs *j, uint64_t *serial, struct ncp_http_msg *msg)
{
    pthread_mutex_lock(&j->mu);
    int got = j->done_n > 0;
    if (got) {
        *serial = j->done[j->done_head].serial;
        *msg = j->done[j->done_head].msg;
        j->done_head = (j->done_head + 1) % JOB_QUEUE;
        j->done_n--;
    }
    pthread_mutex_unlock(&j->mu);
    return got;
}

void ncp_http_jobs_stop(struct ncp_http_jobs *j)
{
    if (!j)
        return;
    pthread_mutex_lock(&j->mu);
    atomic_store(&j->stop, 1);
    pthread_cond_signal(&j->wake);
    pthread_mutex_unlock(&j->mu);
    pthread_join(j->thread, NULL);
    while (j->done_n) {
        free(j->done[j->done_head].msg.buf);
        j->done_head = (j->done_head + 1) % JOB_QUEUE;
        j->done_n--;
    }
    pthread_cond_destroy(&j->wake);
    pthread_mutex_destroy(&j->mu);
    free(j);
}
