/* A pre-started pipeline: the threads of a thread map are created once and run
 * program after program. The interpreter-pipeline paper times each run with
 * thread creation; a user interpreting many short programs (or a benchmark
 * that wants the pipeline's own speed) should not pay it every time. Every run uses the very stage code
 * of ncp_pipeline_run, on rings reset between runs, so its output and errors
 * are the same. */
#include "pipe.h"

#include "futex.h"

#include <stdlib.h>
#include <string.h>

struct pool_member {
    struct ncp_pipeline_pool *pool;
    struct ncp_pipe_worker *w;
    int waits_gate;               /* lexers keep the paper's start rule */
};

struct ncp_pipeline_pool {
    struct ncp_thread_map map;
    struct ncp_pipe *p;
    struct ncp_starter s;
    struct pool_member member[NCP_PIPE_MAX_THREADS];
    _Atomic uint32_t run;         /* bumped to start a run (futex word) */
    _Atomic uint32_t done;        /* members finished with the current run */
    _Atomic int quit;
};

static void *member_main(void *arg)
{
    struct pool_member *m = arg;
    struct ncp_pipeline_pool *pool = m->pool;
    uint32_t seen = 0;
    for (;;) {
        uint32_t run;
        while ((run = atomic_load(&pool->run)) == seen)
            ncp_futex_wait(&pool->run, seen, NULL);
        seen = run;
        if (atomic_load(&pool->quit))
            return NULL;
        if (m->waits_gate)
            ncp_pipe_wait_gate(pool->p, pool->map.start_timeout_us);
        double cpu0 = ncp_pipe_thread_cpu_ms(), sys0 = ncp_pipe_thread_sys_ms();
        ncp_pipe_run_stage(m->w); /* ends with the thread's absolute CPU times in w */
        m->w->cpu_ms -= cpu0;
        m->w->sys_ms -= sys0;
        if (atomic_fetch_add(&pool->done, 1) + 1 == (uint32_t)pool->s.started)
            ncp_futex_wake_all(&pool->done);
    }
}

static void stop_members(struct ncp_pipeline_pool *pool)
{
    atomic_store(&pool->quit, 1);
    atomic_fetch_add(&pool->run, 1);
    ncp_futex_wake_all(&pool->run);
    for (int t = 0; t < pool->s.started; t++)
        pthread_join(pool->s.tid[t], NULL);
    pool->s.started = 0;
}

struct ncp_pipeline_pool *ncp_pipeline_pool_new(const struct ncp_thread_map *map,
                                                struct ncp_diag *d)
{
    memset(d, 0, sizeof *d);
    struct ncp_pipeline_pool *pool = calloc(1, sizeof *pool);
    if (!pool) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the pipeline");
        return NULL;
    }
    pool->map = *map;
    if (map->mode == NCP_MODE_SERIAL)
        return pool; /* the serial reference has no threads to keep */
    pool->p = ncp_pipe_new(&pool->map);
    if (!pool->p) {
        free(pool);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the pipeline rings");
        return NULL;
    }
    atomic_init(&pool->run, 0);
    atomic_init(&pool->done, 0);
    atomic_init(&pool->quit, 0);
    struct ncp_pipe *p = pool->p;
    pool->s.p = p;
    struct ncp_pipe_stage st[NCP_PIPE_MAX_THREADS];
    int n = ncp_pipe_stages(p, st);
    for (int k = 0; k < n && !pool->s.failed; k++) {
        struct pool_member *m = &pool->member[pool->s.started];
        *m = (struct pool_member){ pool, st[k].w, st[k].is_lexer };
        ncp_pipe_start_thread(&pool->s, st[k].spec, member_main, m);
    }
    pool->s.setup_ms = 0; /* the runs never pay it */
    if (pool->s.failed) {
        stop_members(pool);
        ncp_pipe_free(p);
        free(pool);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the pipeline threads");
        return NULL;
    }
    return pool;
}

uint32_t ncp_pipeline_pool_warnings(const struct ncp_pipeline_pool *pool)
{
    return pool->s.warnings;
}

int ncp_pipeline_pool_run(struct ncp_pipeline_pool *pool, const struct ncp_source *src,
                          const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out,
                          struct ncp_run_stats *stats, struct ncp_diag *d)
{
    if (pool->map.mode == NCP_MODE_SERIAL)
        return ncp_serial_run(src, acfg, out, stats, d);
    memset(d, 0, sizeof *d);
    struct ncp_pipe *p = pool->p;
    double t0 = ncp_pipe_now_ms();
    ncp_pipe_reset(p);
    ncp_pipe_set_run(p, src, acfg, out);
    atomic_store(&pool->done, 0);
    atomic_fetch_add(&pool->run, 1);
    ncp_futex_wake_all(&pool->run);
    uint32_t done;
    while ((done = atomic_load(&pool->done)) != (uint32_t)pool->s.started)
        ncp_futex_wait(&pool->done, done, NULL);
    int rc = ncp_pipe_result(p, &pool->s, d);
    if (stats)
        ncp_pipe_fill_stats(p, &pool->s, t0, stats); /* setup_ms 0: nothing started */
    return rc;
}

void ncp_pipeline_pool_free(struct ncp_pipeline_pool *pool)
{
    if (!pool)
        return;
    if (pool->p) {
        stop_members(pool);
        ncp_pipe_free(pool->p);
    }
    free(pool);
}
