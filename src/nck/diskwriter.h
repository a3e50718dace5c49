/* The NCK's disk writer (diskwriter.c): a thread of its own, started with
 * the NCK and ended at its end, writes the job history's lines, the
 * parameter file and the tool table. An fsync may take seconds on an SD
 * card, NFS or a loaded SSD; the service thread, which answers the E-stop,
 * only hands over what to write (memory copies under a lock the writer
 * never holds across I/O) and asks whether the writer has caught up. */
#ifndef NCPAR_NCK_DISKWRITER_H
#define NCPAR_NCK_DISKWRITER_H

#include "history.h"
#include "persist.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>

struct nck_core;

/* history lines waiting: a run waits for the writer before it starts, so
 * one is the most there ever is in practice */
#define NCK_WRITER_LINES 8

struct nck_writer {
    struct nck_core *core;           /* its events */
    const char *hist_path;
    struct nck_persist *persist;     /* the paths and what is handed over; its
                                        tools_base is the thread's */
    pthread_t th;
    int started;
    pthread_mutex_t lock;            /* guards what follows, up to the thread's own */
    pthread_cond_t wake;
    char lines[NCK_WRITER_LINES][NCK_HISTORY_LINE_MAX];
    size_t line_len[NCK_WRITER_LINES];
    int line_head, line_count;
    int queued;                      /* NCK_PERSIST_* bits handed over, not yet taken */
    struct ncp_var_file *vars_next;  /* the newest handed over: the last one wins */
    struct ncp_analyzer *tools_next;
    int working;                     /* the thread writes what it took */
    int quit;                        /* the NCK's end: drain, then end */
    int to_stderr;                   /* nobody reads the events any more */
    atomic_int again;                /* NCK_PERSIST_* bits whose write failed */
    /* the thread's own */
    struct ncp_var_file *vars_work;
    struct ncp_analyzer *tools_work;
    char line_work[NCK_HISTORY_LINE_MAX];
};

/* Starts the thread for the history at hist_path (NULL or "": none) and the
 * files of p. 0, or -1 with d->msg. */
int nck_writer_start(struct nck_writer *w, struct nck_core *core, const char *hist_path,
                     struct nck_persist *p, struct ncp_diag *d);
/* A history line to append after those handed over before: 0, or -1 when
 * NCK_WRITER_LINES wait already (the line is not kept). */
int nck_writer_line(struct nck_writer *w, const char *line, size_t n);
/* The files of changed (NCK_PERSIST_* bits) with the persist's values now
 * (nck_persist_changes), over whatever of them still waits. */
void nck_writer_persist(struct nck_writer *w, int changed);
/* The failed files' bits, cleared: nck_persist_changes's again. */
int nck_writer_again(struct nck_writer *w);
/* 1 while anything handed over waits or is being written; 0 once all of it
 * is written (or failed, said as an event). */
int nck_writer_busy(struct nck_writer *w);
/* The NCK's end: the files of changed with the persist's values handed
 * over last, everything that waits written, then the thread ends; what
 * fails from here on is said on stderr (no event is read after the
 * service). Frees the buffers. */
void nck_writer_stop(struct nck_writer *w, int changed);

#endif
