/* serve's job history ([DISPLAY] HISTORY_FILE, history.c): one JSON line
 * per program run, made on the service thread when the run ends and
 * appended by the NCK's disk writer (diskwriter.h): the append blocks on
 * the disk, which neither the service thread nor the real-time path may
 * wait for. */
#ifndef NCPAR_NCK_HISTORY_H
#define NCPAR_NCK_HISTORY_H

#include <stddef.h>
#include <time.h>

#define NCK_HISTORY_LINE_MAX 1600    /* a line, its newline and a 0 */

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
 * or the reason, its program time and largest following error (mm). Its
 * line in line[cap] (no I/O), and the line's length; 0 (no history, or no
 * run open), or -1 with why in err. */
int nck_history_end(struct nck_history *h, const char *result, const char *why,
                    double program_time, double ferr_max, char *line, size_t cap, char *err,
                    size_t len);
/* Appends the line (n bytes) whole by one write, then fsync: 0, or the
 * errno. Blocks on the disk. */
int nck_history_append(const char *path, const char *line, size_t n);

#endif
