/* src/http's private contract between the socket thread (server.c, gate.c,
 * upload.c) and the slow queries' worker (jobs.c, query.c). */
#ifndef NCP_HTTP_SERVER_INT_H
#define NCP_HTTP_SERVER_INT_H

#include "ncpar/http.h"

#include <libwebsockets.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>

/* The panel's LCM client ids: a tag in the top bits, so its acks are told
 * from cnc-ctl's (whose ids are random) well enough for routing. */
#define NCP_HTTP_CLIENT_TAG ((int32_t)0x57000000)
#define NCP_HTTP_CLIENT_MASK ((int32_t)0x7f000000)
#define NCP_HTTP_STATUS_MAX 8192
#define NCP_HTTP_PROGRAM_MAX (4u << 20)   /* program text the panel shows */

struct ncp_http;

/* The loaded program as the NCK checked it, copied on the serving thread at
 * the load's answer: shared read-only, freed with its last reference. */
struct ncp_http_prog {
    atomic_int refs;
    char path[256];
    size_t len;
    int too_large;              /* over NCP_HTTP_PROGRAM_MAX: text not kept */
    char text[];
};
/* Lets go of a reference (the serving thread's, or the worker's): the last
 * one frees the copy. Inline: both sides let go, and neither is the other's
 * floor. */
static inline void ncp_http_prog_put(struct ncp_http_prog *p)
{
    if (atomic_fetch_sub(&p->refs, 1) == 1)
        free(p);
}

/* A message built off the socket thread: LWS_PRE bytes, then len bytes. */
struct ncp_http_msg {
    unsigned char *buf;
    size_t len;
};

/* What the worker's answers read: cnc-run (the preview's parser), the
 * program folder and the files the Tools and History tabs show (NULL: none
 * kept). */
struct ncp_http_paths {
    const char *self_exe;
    const char *program_dir;    /* the list's folder (ncp_http_opts) */
    const char *tool_table, *history_file;
};

/* The answer to a slow query (list, program, preview, tools, history) or its
 * refusal, on the worker thread (query.c). prog may be NULL (nothing loaded).
 * stop is polled while the preview's interpreter runs. 0, or -1 out of
 * memory. */
int ncp_http_build_answer(const struct ncp_http_paths *paths, const struct ncp_http_prog *prog,
                          enum ncp_http_req r, const atomic_int *stop,
                          struct ncp_http_msg *out);
/* The tool table's or the job history's text as the Tools and History tabs
 * read it ({"type": "tools"|"history", "path": ..., "text": ...}) or the
 * refusal saying why not (files.c): 0, or -1 out of memory. */
int ncp_http_file_answer(const struct ncp_http_paths *paths, enum ncp_http_req r,
                         struct ncp_http_msg *out);

/* The worker (jobs.c): slow queries in order, one at a time, at a lower
 * priority than the socket thread; their answers wait for the socket thread
 * (wake() tells it). A connection is named by its serial number: it may be
 * gone by the time its answer is ready. */
struct ncp_http_jobs;
struct ncp_http_jobs_env {
    struct ncp_http_paths paths;
    struct ncp_http_prog *(*prog_get)(void *ctx);   /* a reference, or NULL */
    void (*wake)(void *ctx);
    void *ctx;
};
struct ncp_http_jobs *ncp_http_jobs_start(const struct ncp_http_jobs_env *env);
/* 0, or -1 when the queue is full. */
int ncp_http_jobs_submit(struct ncp_http_jobs *j, uint64_t serial, enum ncp_http_req r);
/* A finished answer: 1 (the caller owns msg->buf; NULL when there was no
 * memory to build it), or 0 when none. */
int ncp_http_jobs_take(struct ncp_http_jobs *j, uint64_t *serial, struct ncp_http_msg *msg);
void ncp_http_jobs_stop(struct ncp_http_jobs *j);

/* ---- the socket thread's -------------------------------------------------------- */
enum ncp_http_stat {
    NCP_HTTP_STAT_NO_TOKEN, NCP_HTTP_STAT_READONLY, NCP_HTTP_STAT_OVERSIZED,
    NCP_HTTP_STAT_UPLOADS, NCP_HTTP_STAT_UPLOAD_BAD, NCP_HTTP_STAT_FOREIGN_ORIGIN,
    NCP_HTTP_STAT_BAD_HOST, NCP_HTTP_STAT_BAD_REQUEST, NCP_HTTP_STAT_UNAUTH_CLOSED
};
/* What the handlers server.c registers with libwebsockets (gate.c,
 * upload.c) may read of the server, and its calls they may make, handed
 * down as pointers: they call nothing of server.c, which calls them. It is
 * the first member of struct ncp_http, the libwebsockets context's user
 * (server.c asserts that), so a handler finds it from any wsi. */
struct ncp_http_floor {
    const struct ncp_http_opts *opts;
    const struct ncp_http_policy *policy;
    /* one more refusal or upload in the panel's statistics */
    void (*count)(void *ctx, enum ncp_http_stat which);
    /* whether the request's URL carries the token (?token=...) */
    int (*token_ok)(void *ctx, struct lws *wsi);
    void *ctx;
};
static inline const struct ncp_http_floor *ncp_http_floor_of(struct lws *wsi)
{
    return lws_context_user(lws_get_context(wsi));
}
/* A thread of the panel's (the server's loop, the query worker) started with
 * every signal blocked: signals stay with the main thread, which turns them
 * into a controlled stop. pthread_create's result. */
static inline int ncp_http_spawn(pthread_t *t, void *(*fn)(void *), void *arg)
{
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    int rc = pthread_create(t, NULL, fn, arg);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return rc;
}
/* The first callback every HTTP request and upgrade meets (gate.c): Origin,
 * Host and framing (ncp_http_head_verdict) before anything else. */
int ncp_http_on_gate(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                     size_t len);
/* POST /upload (upload.c): libwebsockets' callback and its session's size. */
int ncp_http_on_upload(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                       size_t len);
size_t ncp_http_upload_session_size(void);
/* Removes upload temporaries older than max_age_s left by a serve that was
 * killed mid-upload: the number removed. */
int ncp_http_sweep_uploads(const char *folder, int max_age_s);

#endif
