/* table3: runs one interpreter configuration RUNS times in one process, for the
 * Table 3 reproduction (the interpreter-pipeline paper) in `make bench`.
 *
 *   table3 PROG MAP.ini RUNS [--tool-table FILE] [--warmup N] [--max-seconds S]
 *
 * One process for all runs keeps exec, mmap and page-cache effects out of the
 * timings: the program is mapped once and every run sees the same warm text.
 * Each run is timed by the library itself (ncp_run_stats.wall_ms: pipeline start,
 * thread creation included, to the last command out; setup_ms: the part of it the
 * starting thread spent allocating rings and creating threads), and each is
 * followed by a run of the same program on a pre-started pool of the same map
 * (ncp_pipeline_pool_run: threads created once, rings reset between runs): the
 * time without thread creation, measured rather than estimated.
 *
 * The emitted canonical text is copied into a buffer as `cnc-run parse --canon`
 * does, so the output stage does the same work, but never written. The first
 * (untimed) warm-up run hashes that text instead (FNV-1a), so the caller can check
 * that every configuration produced the serial reference's output.
 *
 * --max-seconds bounds the timed runs of a slow configuration so that the whole
 * suite keeps its time budget; fewer runs are then reported ("stopped" line).
 *
 * stdout: "warning TEXT" lines, "hash H blocks B commands C", then one line
 * "run I WALL_MS SETUP_MS POOL_MS" per timed run, and "stopped N" if the time ran
 * out.
 * Exit 0, 1 usage, 2 program error. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "ncpar/pipeline.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct sink {
    int hashing;
    uint64_t hash;
    size_t used;
    char buf[1 << 20];
};

static int emit(void *ctx, const struct ncp_cmd *cmd)
{
    struct sink *s = ctx;
    if (s->hashing) {
        for (uint32_t i = 0; i < cmd->out_len; i++) {
            s->hash ^= (unsigned char)cmd->out[i];
            s->hash *= 1099511628211ull;
        }
        return 0;
    }
    if (s->used + cmd->out_len > sizeof s->buf)
        s->used = 0;
    memcpy(s->buf + s->used, cmd->out, cmd->out_len);
    s->used += cmd->out_len;
    return 0;
}

/* The serial reference runs in the calling thread: give it the feeder's placement,
 * as the paper ran its serial version on CPU0. In the "Prio 90" runs the paper gave
 * every thread of the application priority 90, the starting one included; that
 * also keeps the freshly created SCHED_FIFO threads from preempting it on its own
 * CPU while it creates the rest, which would count their work as start-up time. */
static void place_self(const struct ncp_rt_place *spec, int pin)
{
    if (pin && spec->cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(spec->cpu, &set);
        if (sched_setaffinity(0, sizeof set, &set))
            printf("warning cannot pin the serial run to CPU %d: %s\n", spec->cpu,
                   strerror(errno));
    }
    if (spec->policy == SCHED_FIFO) {
        struct sched_param p = { .sched_priority = spec->priority };
        if (sched_setscheduler(0, SCHED_FIFO, &p))
            printf("warning SCHED_FIFO not permitted, starting thread is SCHED_OTHER: %s\n",
                   strerror(errno));
    }
}

/* One run: with thread creation (pool NULL) or on the pre-started pool. */
static int run_once(const struct ncp_source *src, const struct ncp_thread_map *map,
                    struct ncp_pipeline_pool *pool, const struct ncp_analyzer_cfg *acfg,
                    struct sink *s, struct ncp_run_stats *st, struct ncp_diag *d)
{
    struct ncp_output out = { .ctx = s, .emit = emit };
    memset(st, 0, sizeof *st);
    memset(d, 0, sizeof *d);
    s->used = 0;
    if (pool)
        return ncp_pipeline_pool_run(pool, src, acfg, &out, st, d);
    return map->mode == NCP_MODE_SERIAL ? ncp_serial_run(src, acfg, &out, st, d)
                                        : ncp_pipeline_run(src, map, acfg, &out, st, d);
}

static void report_warnings(uint32_t *seen, uint32_t w)
{
    w &= ~*seen;
    *seen |= w;
    const char *text;
    while ((text = ncp_run_warning_next(&w)) != NULL)
        printf("warning %s\n", text);
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int usage(void)
{
    fputs("usage: table3 PROG MAP.ini RUNS [--tool-table FILE] [--warmup N] [--max-seconds S]\n",
          stderr);
    return 1;
}

struct opts {
    const char *prog, *map_path;
    long runs, warmup;
    double max_s;
    struct ncp_analyzer_cfg acfg;
};

static int parse_opts(int argc, char **argv, struct opts *o)
{
    memset(o, 0, sizeof *o);
    if (argc < 4)
        return -1;
    o->prog = argv[1];
    o->map_path = argv[2];
    o->runs = strtol(argv[3], NULL, 10);
    o->warmup = 1;
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--tool-table") && i + 1 < argc)
            o->acfg.tool_table_path = argv[++i];
        else if (!strcmp(argv[i], "--warmup") && i + 1 < argc)
            o->warmup = strtol(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--max-seconds") && i + 1 < argc)
            o->max_s = strtod(argv[++i], NULL);
        else
            return -1;
    }
    return o->runs < 1 || o->warmup < 1 ? -1 : 0;
}

/* Warm-up runs (the first one hashed), then the timed runs. Returns the exit status. */
static int measure(const struct opts *o, const struct ncp_source *src,
                   const struct ncp_thread_map *map, struct sink *s,
                   struct ncp_pipeline_pool *pool)
{
    struct ncp_run_stats st, pst;
    struct ncp_diag d;
    uint32_t seen = 0;
    report_warnings(&seen, ncp_pipeline_pool_warnings(pool));
    s->hashing = 1;
    s->hash = 14695981039346656037ull;
    for (long i = 0; i < o->warmup; i++) {
        if (run_once(src, map, NULL, &o->acfg, s, &st, &d) != NCP_OK ||
            run_once(src, map, pool, &o->acfg, s, &pst, &d) != NCP_OK) {
            fprintf(stderr, "%s:%u:%u: error: %s\n", o->prog, d.line, d.col, d.msg);
            return 2;
        }
        report_warnings(&seen, st.warnings);
        if (i == 0)
            printf("hash %016llx blocks %llu commands %llu\n", (unsigned long long)s->hash,
                   (unsigned long long)st.blocks, (unsigned long long)st.commands);
        s->hashing = 0;
    }
    double t0 = now_s();
    for (long i = 0; i < o->runs; i++) {
        if (o->max_s > 0 && i > 0 && now_s() - t0 > o->max_s) {
            printf("stopped %ld\n", i);
            break;
        }
        if (run_once(src, map, NULL, &o->acfg, s, &st, &d) != NCP_OK ||
            run_once(src, map, pool, &o->acfg, s, &pst, &d) != NCP_OK) {
            fprintf(stderr, "%s:%u:%u: error: %s\n", o->prog, d.line, d.col, d.msg);
            return 2;
        }
        report_warnings(&seen, st.warnings);
        printf("run %ld %.6f %.6f %.6f\n", i, st.wall_ms, st.setup_ms, pst.wall_ms);
    }
    return 0;
}

int main(int argc, char **argv)
{
    struct opts o;
    if (parse_opts(argc, argv, &o))
        return usage();
    struct ncp_diag d;
    struct ncp_thread_map map;
    if (ncp_thread_map_load(&map, o.map_path, &d) != NCP_OK) {
        fprintf(stderr, "%s:%u: error: %s\n", o.map_path, d.line, d.msg);
        return 1;
    }
    struct ncp_source src;
    if (ncp_source_open(&src, o.prog, &d) != NCP_OK) {
        fprintf(stderr, "%s: error: %s\n", o.prog, d.msg);
        return 2;
    }
    place_self(&map.feeder, map.mode == NCP_MODE_SERIAL);
    struct sink *s = calloc(1, sizeof *s);
    struct ncp_pipeline_pool *pool = ncp_pipeline_pool_new(&map, &d);
    if (!pool)
        fprintf(stderr, "table3: %s\n", d.msg);
    int status = s && pool ? measure(&o, &src, &map, s, pool) : 1;
    ncp_pipeline_pool_free(pool);
    free(s);
    ncp_source_close(&src);
    return status;
}
