/* The job history (history.h). A line is written whole by one write(2) to
 * a file opened for appending, then fsync'd: a crash leaves the lines
 * before it whole, and at worst the last one missing, never half of it
 * among the others. JSON, one object a line, so that a reader needs no
 * parser of ours (cnc-ctl history, jq, a spreadsheet's import). */
#include "history.h"

#include <errno.h>
#include <fcntl.h>
#include <openssl/sha.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

void nck_history_begin(struct nck_history *h, const char *program, const char *text,
                       size_t len, double estimate)
{
    if (!h->path || !h->path[0])
        return;
    clock_gettime(CLOCK_REALTIME, &h->start);
    snprintf(h->program, sizeof h->program, "%s", program);
    /* which program ran, whatever its file was renamed to or holds since */
    unsigned char md[SHA256_DIGEST_LENGTH];
    SHA256((const unsigned char *)(text ? text : ""), text ? len : 0, md);
    for (size_t i = 0; i < SHA256_DIGEST_LENGTH; i++)
        snprintf(h->sha256 + 2 * i, 3, "%02x", md[i]);
    h->estimate = estimate;
    h->open = 1;
}

/* s as a JSON string's contents: quotes, backslashes and control
 * characters escaped (a path or a message may hold any of them). */
static size_t json_text(char *out, size_t cap, const char *s)
{
    size_t k = 0;
    for (; *s && k + 7 < cap; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            k += (size_t)snprintf(out + k, cap - k, "\\%c", c);
        else if (c < 0x20)
            k += (size_t)snprintf(out + k, cap - k, "\\u%04x", c);
        else
            out[k++] = (char)c;
    }
    out[k] = 0;
    return k;
}

static void iso_time(char *out, size_t cap, const struct timespec *t)
{
    struct tm tm;
    gmtime_r(&t->tv_sec, &tm);
    char base[32];
    strftime(base, sizeof base, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(out, cap, "%s.%03ldZ", base, t->tv_nsec / 1000000);
}

int nck_history_append(const char *path, const char *line, size_t n)
{
    int fd = open(path, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        return errno;
    ssize_t w;
    do
        w = write(fd, line, n);
    while (w < 0 && errno == EINTR);
    int err = w < 0 ? errno : (size_t)w != n ? EIO : 0;
    if (!err && fsync(fd) != 0)
        err = errno;
    if (close(fd) != 0 && !err)
        err = errno;
    return err;
}

int nck_history_end(struct nck_history *h, const char *result, const char *why,
                    double program_time, double ferr_max, char *line, size_t cap, char *err,
                    size_t len)
{
    if (!h->open)
        return 0;
    h->open = 0;
    struct timespec end;
    clock_gettime(CLOCK_REALTIME, &end);
    char t0[40], t1[40], prog[600], reason[600], est[32];
    iso_time(t0, sizeof t0, &h->start);
    iso_time(t1, sizeof t1, &end);
    json_text(prog, sizeof prog, h->program);
    json_text(reason, sizeof reason, why ? why : "");
    if (h->estimate >= 0)
        snprintf(est, sizeof est, "%.6f", h->estimate);
    else
        snprintf(est, sizeof est, "null");
    int n = snprintf(line, cap,
                     "{\"start\": \"%s\", \"end\": \"%s\", \"program\": \"%s\", \"sha256\": "
                     "\"%s\", \"result\": \"%s\", \"reason\": \"%s\", \"program_time_s\": %.6f, "
                     "\"max_following_error_mm\": %.6f, \"estimate_s\": %s}\n",
                     t0, t1, prog, h->sha256, result, reason, program_time, ferr_max, est);
    if (n < 0 || (size_t)n >= cap)
        return snprintf(err, len, "history: the line for %s is too long", h->program), -1;
    return n;
}
