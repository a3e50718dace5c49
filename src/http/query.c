/* What the panel reads besides the status: the programs in the NCK's folder
 * (its working directory, where LOAD's relative paths start), the loaded
 * program's text, and its canonical commands for the 3D preview. The preview
 * is `cnc-run parse PROG --canon -` in a child process: the same interpreter
 * path as everywhere, and a program that takes long to interpret delays the
 * panel's thread, never the NCK. */
#include "server_int.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define PROGRAM_MAX (4u << 20)      /* program text shown in the panel */
#define CANON_MAX (32u << 20)       /* preview: canonical text read from parse */
#define PREVIEW_TIMEOUT_MS 10000
#define LIST_MAX 500

extern char **environ;

struct buf {
    char *p;
    size_t len, size;
};

static int buf_reserve(struct buf *b, size_t more)
{
    if (b->len + more <= b->size)
        return 0;
    size_t size = b->size ? b->size : 4096;
    while (size < b->len + more)
        size *= 2;
    char *p = realloc(b->p, size);
    if (!p)
        return -1;
    b->p = p;
    b->size = size;
    return 0;
}

static int buf_put(struct buf *b, const char *s)
{
    size_t n = strlen(s);
    if (buf_reserve(b, n + 1))
        return -1;
    memcpy(b->p + b->len, s, n + 1);
    b->len += n;
    return 0;
}

static int buf_json(struct buf *b, const char *s, size_t n)
{
    if (buf_reserve(b, 6 * n + 3))
        return -1;
    return ncp_http_json_string(b->p, b->size, &b->len, s, n);
}

static int has_suffix(const char *name, const char *suffix)
{
    size_t n = strlen(name), k = strlen(suffix);
    return n > k && !strcasecmp(name + n - k, suffix);
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void list(struct ncp_http *h, struct conn *c)
{
    DIR *dir = opendir(".");
    if (!dir) {
        ncp_http_refuse(h, c, 0, "cannot read the NCK's folder");
        return;
    }
    char *names[LIST_MAX] = { 0 };
    int n = 0;
    struct dirent *e;
    while (n < LIST_MAX && (e = readdir(dir))) {
        struct stat st;
        if ((has_suffix(e->d_name, ".ngc") || has_suffix(e->d_name, ".nc") ||
             has_suffix(e->d_name, ".tap")) && stat(e->d_name, &st) == 0 && S_ISREG(st.st_mode))
            if ((names[n] = strdup(e->d_name)))
                n++;
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof names[0], cmp_names);
    struct buf b = { 0 };
    int bad = buf_put(&b, "{\"type\": \"list\", \"files\": [");
    for (int i = 0; i < n; i++) {
        bad |= i ? buf_put(&b, ", ") : 0;
        bad |= buf_json(&b, names[i], strlen(names[i]));
        free(names[i]);
    }
    bad |= buf_put(&b, "]}");
    if (!bad)
        ncp_http_send(h, c, b.p, b.len);
    free(b.p);
}

/* The whole of path, at most max bytes: 0, or -1 with why. */
static int slurp(const char *path, size_t max, struct buf *out, char *why, size_t wl)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        snprintf(why, wl, "cannot read %s: %s", path, fd < 0 ? strerror(errno) : "not a file");
        if (fd >= 0)
            close(fd);
        return -1;
    }
    if ((size_t)st.st_size > max) {
        snprintf(why, wl, "%s is too large to show (%lld bytes, at most %zu)", path,
                 (long long)st.st_size, max);
        close(fd);
        return -1;
    }
    if (buf_reserve(out, (size_t)st.st_size + 1)) {
        close(fd);
        return snprintf(why, wl, "out of memory"), -1;
    }
    ssize_t r;
    while (out->len < out->size - 1 && (r = read(fd, out->p + out->len, out->size - 1 - out->len)) > 0)
        out->len += (size_t)r;
    close(fd);
    return 0;
}

static void program(struct ncp_http *h, struct conn *c, const char *path)
{
    char why[320];
    struct buf text = { 0 }, b = { 0 };
    if (!*path) {
        ncp_http_refuse(h, c, 0, "no program loaded");
        return;
    }
    if (slurp(path, PROGRAM_MAX, &text, why, sizeof why)) {
        ncp_http_refuse(h, c, 0, why);
        free(text.p);
        return;
    }
    int bad = buf_put(&b, "{\"type\": \"program\", \"path\": ");
    bad |= buf_json(&b, path, strlen(path));
    bad |= buf_put(&b, ", \"text\": ");
    bad |= buf_json(&b, text.p ? text.p : "", text.len);
    bad |= buf_put(&b, "}");
    if (!bad)
        ncp_http_send(h, c, b.p, b.len);
    free(text.p);
    free(b.p);
}

static int64_t mono_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* `self parse path --canon -`'s output (stdout and stderr) into out. */
static int run_parse(const char *self, const char *path, struct buf *out, char *why, size_t wl)
{
    int fds[2];
    if (pipe2(fds, O_CLOEXEC))
        return snprintf(why, wl, "preview: %s", strerror(errno)), -1;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
    posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
    char *argv[] = { (char *)self, "parse", (char *)path, "--canon", "-", NULL };
    pid_t pid;
    int rc = posix_spawn(&pid, self, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(fds[1]);
    if (rc) {
        close(fds[0]);
        return snprintf(why, wl, "preview: cannot run %s: %s", self, strerror(rc)), -1;
    }
    int64_t deadline = mono_ms() + PREVIEW_TIMEOUT_MS;
    int fail = 0;
    for (;;) {
        int64_t left = deadline - mono_ms();
        struct pollfd p = { fds[0], POLLIN, 0 };
        if (left <= 0 || poll(&p, 1, (int)left) <= 0) {
            fail = snprintf(why, wl, "preview: the interpreter took over %d s",
                            PREVIEW_TIMEOUT_MS / 1000);
            break;
        }
        if (out->len >= CANON_MAX) {
            fail = snprintf(why, wl, "preview: more than %u MB of commands", CANON_MAX >> 20);
            break;
        }
        if (buf_reserve(out, 65536)) {
            fail = snprintf(why, wl, "preview: out of memory");
            break;
        }
        ssize_t r = read(fds[0], out->p + out->len, 65536);
        if (r <= 0)
            break;
        out->len += (size_t)r;
    }
    close(fds[0]);
    if (fail)
        kill(pid, SIGKILL);
    while (waitpid(pid, NULL, 0) < 0 && errno == EINTR)
        ;
    return fail ? -1 : 0;
}

static void preview(struct ncp_http *h, struct conn *c, const char *path)
{
    char why[320];
    struct buf canon = { 0 }, b = { 0 };
    if (!*path) {
        ncp_http_refuse(h, c, 0, "no program loaded");
        return;
    }
    if (run_parse(ncp_http_opts_of(h)->self_exe, path, &canon, why, sizeof why)) {
        ncp_http_refuse(h, c, 0, why);
        free(canon.p);
        return;
    }
    int bad = buf_put(&b, "{\"type\": \"preview\", \"path\": ");
    bad |= buf_json(&b, path, strlen(path));
    bad |= buf_put(&b, ", \"canon\": ");
    bad |= buf_json(&b, canon.p ? canon.p : "", canon.len);
    bad |= buf_put(&b, "}");
    if (!bad)
        ncp_http_send(h, c, b.p, b.len);
    free(canon.p);
    free(b.p);
}

void ncp_http_answer_query(struct ncp_http *h, struct conn *c, enum ncp_http_req r,
                           const char *path)
{
    if (r == NCP_HTTP_REQ_LIST)
        list(h, c);
    else if (r == NCP_HTTP_REQ_PROGRAM)
        program(h, c, path);
    else if (r == NCP_HTTP_REQ_PREVIEW)
        preview(h, c, path);
}
