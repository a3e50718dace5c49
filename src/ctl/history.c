/* cnc-ctl history: the job history a serving NCK appends to ([DISPLAY]
 * HISTORY_FILE, whose path it gives on request), read from the file on this host:
 * newest last, the last N jobs. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctl.h"

/* The value of "key": in one of the NCK's history lines, unescaped
 * (strings) or as written (numbers, null); "" when absent. */
static void field(const char *line, const char *key, char *out, size_t cap)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *p = strstr(line, pat);
    size_t k = 0;
    if (p) {
        p += strlen(pat);
        if (*p == '"') {
            for (p++; *p && *p != '"' && k + 1 < cap; p++) {
                if (*p == '\\' && p[1])
                    p++;
                out[k++] = *p;
            }
        } else {
            for (; *p && *p != ',' && *p != '}' && k + 1 < cap; p++)
                out[k++] = *p;
        }
    }
    out[k] = 0;
}

static void print_line(const char *line, int json)
{
    if (json) {
        fputs(line, stdout);
        return;
    }
    char start[48], result[16], reason[600], prog[600], t[32], est[32], ferr[32];
    field(line, "start", start, sizeof start);
    field(line, "result", result, sizeof result);
    field(line, "reason", reason, sizeof reason);
    field(line, "program", prog, sizeof prog);
    field(line, "program_time_s", t, sizeof t);
    field(line, "estimate_s", est, sizeof est);
    field(line, "max_following_error_mm", ferr, sizeof ferr);
    char times[120];
    if (strcmp(est, "null") != 0 && est[0])
        snprintf(times, sizeof times, "%9.3f s (estimate %.3f s)", atof(t), atof(est));
    else
        snprintf(times, sizeof times, "%9.3f s", atof(t));
    if (ferr[0]) {
        size_t k = strlen(times);
        snprintf(times + k, sizeof times - k, "  ferr %.4f mm", atof(ferr));
    }
    printf("%s  %-8s %s  %s%s%s\n", start, result, times, prog, reason[0] ? ": " : "", reason);
}

int ctl_file_path(struct ctl *c, const char *which, char *path, size_t len)
{
    ncp_command_t cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.kind = NCP_COMMAND_T_FILES;
    snprintf((char *)cmd.text, sizeof cmd.text, "%s", which);
    int rc = ctl_command(c, &cmd);
    if (rc == CTL_OK)
        snprintf(path, len, "%.*s", (int)strnlen((const char *)c->ack.reason, sizeof c->ack.reason),
                 (const char *)c->ack.reason);
    return rc;
}

int ctl_history(struct ctl *c, int json, long last)
{
    char path[300];
    int rc = ctl_file_path(c, "history", path, sizeof path);
    if (rc != CTL_OK)
        return rc;
    FILE *f = fopen(path, "r");
    if (!f && errno == ENOENT)
        return CTL_OK;   /* no job has ended yet */
    if (!f) {
        fprintf(stderr, "cnc-ctl: history: %s: %s (it is on the NCK's host)\n", path,
                strerror(errno));
        return CTL_REJECTED;
    }
    /* the last `last` lines, in a ring of them */
    size_t n = last > 0 ? (size_t)last : 1;
    char **ring = calloc(n, sizeof *ring);
    size_t seen = 0;
    char *line = NULL;
    size_t cap = 0;
    while (ring && getline(&line, &cap, f) > 0) {
        if (line[0] != '{')
            continue;   /* not one of ours: a hand edit */
        free(ring[seen % n]);
        ring[seen % n] = line;
        line = NULL;
        cap = 0;
        seen++;
    }
    free(line);
    fclose(f);
    if (!ring) {
        fprintf(stderr, "cnc-ctl: history: out of memory\n");
        return CTL_USAGE;
    }
    size_t from = seen > n ? seen - n : 0;
    for (size_t i = from; i < seen; i++)
        print_line(ring[i % n], json);
    for (size_t i = 0; i < n; i++)
        free(ring[i]);
    free(ring);
    return CTL_OK;
}
