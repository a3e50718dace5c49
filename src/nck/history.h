/* serve's job history ([DISPLAY] HISTORY_FILE, history.c): one JSON line
 * per program run, appended when it ends. Runs on the service thread
 * between jobs, never on the real-time path (the write blocks on the
 * disk). */
#ifndef NCPAR_NCK_HISTORY_H
#define NCPAR_NCK_HISTORY_H

#include <stddef.h>
#include <time.h>

struct nck_history {
    const char *path;                /* NULL or "": no history */
    int open;                        /* a run began and its line is not written yet */
    struct timespec start;           /* CLOCK_REALTIME */
    char program[256];
    char sha256[65];                 /* of the text the run interprets, hex */
    double estimate;                 /* s, < 0: none was ready */
};

/* A program run begins (nothing written yet): its path, the text the load
 * checked (len bytes: what runs, whatever the file holds by now) and the
 * load's estimate. */
void nck_history_begin(struct nck_history *h, const char *program, const char *text,
                       size_t len, double estimate);
/* It ended: result "done", "error", "stopped", "estop" or "fault", why ""
 * or the reason, its program time and largest following error (mm). 0
 * (written, or no history, or no run open), or -1 with why in err. */
int nck_history_end(struct nck_history *h, const char *result, const char *why,
                    double program_time, double ferr_max, char *err, size_t len);

#endif
