/* The NCK's disk writer (diskwriter.h). The lock is held for copies and
 * pointer swaps only: the service thread that takes it to hand something
 * over never waits for a disk. Lines go first, in the order handed over;
 * the files after them, each as last handed over. */
#include "diskwriter.h"
#include "nck_int.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An event while the service reads them, else stderr (the NCK's end). */
static void say(struct nck_writer *w, int to_stderr, int kind, const char *text)
{
    if (!to_stderr)
        nck_post(w->core, kind, NULL, 0, 0, "%s", text);
    else if (kind == NCP_EV_ERROR)
        fprintf(stderr, "cnc-run serve: error: %s\n", text);
}

static void write_files(struct nck_writer *w, int what, int to_stderr)
{
    struct nck_persist *p = w->persist;
    char why[NCP_DIAG_MSG_MAX], text[NCP_DIAG_MSG_MAX + 64];
    if (what & NCK_PERSIST_VARS) {
        int rc = nck_persist_write_vars(p->var_path, w->vars_work, why, sizeof why);
        if (rc < 0) {
            atomic_fetch_or(&w->again, NCK_PERSIST_VARS);   /* the next job's end tries again */
            say(w, to_stderr, NCP_EV_ERROR, why);
        } else {
            snprintf(text, sizeof text, "offsets saved to %s", p->var_path);
            say(w, to_stderr, NCP_EV_INFO, text);
        }
    }
    if (what & NCK_PERSIST_TOOLS) {
        int rc = nck_persist_write_tools(p->tool_path, w->tools_work, p->tools_base, why,
                                         sizeof why);
        if (rc < 0) {
            atomic_fetch_or(&w->again, NCK_PERSIST_TOOLS);
            say(w, to_stderr, NCP_EV_ERROR, why);
        } else if (rc > 0) {
            snprintf(text, sizeof text, "tool table %s written", p->tool_path);
            say(w, to_stderr, NCP_EV_INFO, text);
        }
    }
}

static void *writer_main(void *arg)
{
    struct nck_writer *w = arg;
    pthread_mutex_lock(&w->lock);
    for (;;) {
        while (!w->line_count && !w->queued && !w->quit)
            pthread_cond_wait(&w->wake, &w->lock);
        if (!w->line_count && !w->queued)
            break;   /* quit, and nothing is left */
        size_t n = 0;
        int what = 0;
        if (w->line_count) {
            n = w->line_len[w->line_head];
            memcpy(w->line_work, w->lines[w->line_head], n);
            w->line_head = (w->line_head + 1) % NCK_WRITER_LINES;
            w->line_count--;
        } else {
            what = w->queued;
            w->queued = 0;
            struct ncp_var_file *vf = w->vars_work;
            w->vars_work = w->vars_next;
            w->vars_next = vf;
            struct ncp_analyzer *t = w->tools_work;
            w->tools_work = w->tools_next;
            w->tools_next = t;
        }
        w->working = 1;
        int to_stderr = w->to_stderr;
        pthread_mutex_unlock(&w->lock);
        if (n) {
            int e = nck_history_append(w->hist_path, w->line_work, n);
            if (e) {
                char why[NCP_DIAG_MSG_MAX];
                snprintf(why, sizeof why, "cannot append to the job history %s ([DISPLAY] "
                         "HISTORY_FILE): %s", w->hist_path, strerror(e));
                say(w, to_stderr, NCP_EV_ERROR, why);
            }
        } else {
            write_files(w, what, to_stderr);
        }
        pthread_mutex_lock(&w->lock);
        w->working = 0;
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

static void free_buffers(struct nck_writer *w)
{
    free(w->vars_next);
    free(w->vars_work);
    ncp_analyzer_free(w->tools_next);
    ncp_analyzer_free(w->tools_work);
    w->vars_next = w->vars_work = NULL;
    w->tools_next = w->tools_work = NULL;
}

int nck_writer_start(struct nck_writer *w, struct nck_core *core, const char *hist_path,
                     struct nck_persist *p, struct ncp_diag *d)
{
    memset(w, 0, sizeof *w);
    w->core = core;
    w->hist_path = hist_path;
    w->persist = p;
    atomic_init(&w->again, 0);
    /* buffers for what is handed over, made here: nothing is allocated
     * while the NCK serves */
    int ok = 1;
    if (p->vf)
        ok = (w->vars_next = malloc(sizeof *w->vars_next)) &&
             (w->vars_work = malloc(sizeof *w->vars_work));
    if (ok && p->tool_path)
        ok = (w->tools_next = ncp_analyzer_new(NULL, d)) &&
             (w->tools_work = ncp_analyzer_new(NULL, d));
    if (!ok) {
        free_buffers(w);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory"), -1;
    }
    pthread_mutex_init(&w->lock, NULL);
    pthread_cond_init(&w->wake, NULL);
    if (pthread_create(&w->th, NULL, writer_main, w) != 0) {
        pthread_cond_destroy(&w->wake);
        pthread_mutex_destroy(&w->lock);
        free_buffers(w);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the disk writer's thread"), -1;
    }
    w->started = 1;
    return 0;
}

int nck_writer_line(struct nck_writer *w, const char *line, size_t n)
{
    if (!w->started || n > NCK_HISTORY_LINE_MAX)
        return -1;
    pthread_mutex_lock(&w->lock);
    int full = w->line_count == NCK_WRITER_LINES;
    if (!full) {
        int k = (w->line_head + w->line_count) % NCK_WRITER_LINES;
        memcpy(w->lines[k], line, n);
        w->line_len[k] = n;
        w->line_count++;
        pthread_cond_signal(&w->wake);
    }
    pthread_mutex_unlock(&w->lock);
    return full ? -1 : 0;
}

/* under the lock */
static void hand_over(struct nck_writer *w, int changed)
{
    const struct nck_persist *p = w->persist;
    int taken = 0;
    if ((changed & NCK_PERSIST_VARS) && p->vf) {
        memcpy(w->vars_next, p->vf, sizeof *w->vars_next);
        taken |= NCK_PERSIST_VARS;
    }
    if ((changed & NCK_PERSIST_TOOLS) && p->tool_path) {
        ncp_analyzer_copy_tools(w->tools_next, p->tools_sent);
        taken |= NCK_PERSIST_TOOLS;
    }
    if (!taken)
        return;
    w->queued |= taken;
    pthread_cond_signal(&w->wake);
}

void nck_writer_persist(struct nck_writer *w, int changed)
{
    if (!w->started)
        return;
    pthread_mutex_lock(&w->lock);
    hand_over(w, changed);
    pthread_mutex_unlock(&w->lock);
}

int nck_writer_again(struct nck_writer *w)
{
    return atomic_exchange(&w->again, 0);
}

int nck_writer_busy(struct nck_writer *w)
{
    if (!w->started)
        return 0;
    pthread_mutex_lock(&w->lock);
    int busy = w->line_count || w->queued || w->working;
    pthread_mutex_unlock(&w->lock);
    return busy;
}

void nck_writer_stop(struct nck_writer *w, int changed)
{
    if (!w->started)
        return;
    pthread_mutex_lock(&w->lock);
    w->to_stderr = 1;
    hand_over(w, changed);
    w->quit = 1;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->th, NULL);
    w->started = 0;
    pthread_cond_destroy(&w->wake);
    pthread_mutex_destroy(&w->lock);
    free_buffers(w);
}
