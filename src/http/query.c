/* What the panel reads besides the status, built on the worker thread
 * (jobs.c), never on the socket thread that carries the commands: the
 * programs in the NCK's folder (its working directory, where LOAD's relative
 * paths start), the loaded program's text and its canonical commands for
 * the 3D preview.
 *
 * Text and preview come from the copy the NCK checked and runs, not from
 * the file, which may have been written over since the load: the operator
 * sees what runs. The preview is `cnc-run parse --canon -` of that copy in a
 * child process (the same interpreter path as everywhere), bounded in wall
 * time (killed after PREVIEW_TIMEOUT_MS), in CPU time (RLIMIT_CPU) and in
 * output (CANON_MAX), niced below the service. */
#include "server_int.h"
#include "ncpar/clock.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define CANON_MAX (32u << 20)       /* preview: canonical text read from parse */
#define PREVIEW_TIMEOUT_MS 10000
#define PREVIEW_CPU_S 10
#define PREVIEW_NICE 10
#define LIST_MAX 500

extern char **environ;

/* A message under construction, LWS_PRE bytes kept free in front. */
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

static int buf_start(struct buf *b)
{
    memset(b, 0, sizeof *b);
    if (buf_reserve(b, LWS_PRE + 256))
        return -1;
    b->len = LWS_PRE;
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

/* The escaped length, so that a large text is escaped into one allocation
 * of its own size, not six times it. */
static size_t json_len(const char *s, size_t n)
{
    size_t k = 2;
    for (size_t i = 0; i < n; i++) {
        unsigned char ch = (unsigned char)s[i];
        k += ch == '"' || ch == '\\' || ch == '\n' ? 2 : ch < 0x20 || ch == 0x7f ? 6 : 1;
    }
    return k;
}

static int buf_json(struct buf *b, const char *s, size_t n)
{
    if (buf_reserve(b, json_len(s, n) + 8))
        return -1;
    return ncp_http_json_string(b->p, b->size, &b->len, s, n);
}

static int finish(struct buf *b, int bad, struct ncp_http_msg *out)
{
    if (bad) {
        free(b->p);
        return -1;
    }
    out->buf = (unsigned char *)b->p;
    out->len = b->len - LWS_PRE;
    return 0;
}

static int refusal(const char *why, struct ncp_http_msg *out)
{
    struct buf b;
    if (buf_start(&b))
        return -1;
    int bad = buf_put(&b, "{\"type\": \"refused\", \"seq\": 0, \"reason\": ");
    bad |= buf_json(&b, why, strlen(why));
    bad |= buf_put(&b, "}");
    return finish(&b, bad, out);
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

static int list(const char *program_dir, struct ncp_http_msg *out)
{
    DIR *dir = opendir(program_dir && program_dir[0] ? program_dir : ".");
    if (!dir)
        return refusal("cannot read the program folder", out);
    int fd = dirfd(dir);
    char **names = calloc(LIST_MAX, sizeof *names);
    if (!names) {
        closedir(dir);
        return -1;
    }
    int n = 0;
    struct dirent *e;
    while (n < LIST_MAX && (e = readdir(dir))) {
        struct stat st;
        if ((has_suffix(e->d_name, ".ngc") || has_suffix(e->d_name, ".nc") ||
             has_suffix(e->d_name, ".tap")) && fstatat(fd, e->d_name, &st, 0) == 0 &&
            S_ISREG(st.st_mode))
            if ((names[n] = strdup(e->d_name)))
                n++;
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof names[0], cmp_names);
    struct buf b;
    int bad = buf_start(&b);
    bad |= bad ? 0 : buf_put(&b, "{\"type\": \"list\", \"files\": [");
    for (int i = 0; i < n; i++) {
        if (!bad) {
            bad |= i ? buf_put(&b, ", ") : 0;
            bad |= buf_json(&b, names[i], strlen(names[i]));
        }
        free(names[i]);
    }
    free(names);
    if (bad) {
        free(b.p);
        return -1;
    }
    return finish(&b, buf_put(&b, "]}"), out);
}

static int program(const struct ncp_http_prog *prog, struct ncp_http_msg *out)
{
    if (!prog)
        return refusal("no program loaded", out);
    if (prog->too_large) {
        char why[320];
        snprintf(why, sizeof why, "%s is too large to show (%zu bytes, at most %u)", prog->path,
                 prog->len, NCP_HTTP_PROGRAM_MAX);
        return refusal(why, out);
    }
    struct buf b;
    if (buf_start(&b))
        return -1;
    int bad = buf_put(&b, "{\"type\": \"program\", \"path\": ");
    bad |= buf_json(&b, prog->path, strlen(prog->path));
    bad |= buf_put(&b, ", \"text\": ");
    bad |= buf_json(&b, prog->text, prog->len);
    bad |= buf_put(&b, "}");
    return finish(&b, bad, out);
}

/* The checked text where the child can open it by name: an unnamed file in
 * memory (nothing lands in the program folder, nothing outlives us). */
static int text_file(const struct ncp_http_prog *prog)
{
    int fd = memfd_create("ncp-preview", MFD_CLOEXEC);
    if (fd < 0)
        return -1;
    size_t done = 0;
    while (done < prog->len) {
        ssize_t w = write(fd, prog->text + done, prog->len - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            close(fd);
            return -1;
        }
        done += (size_t)w;
    }
    return fd;
}

/* Limits on a child already running: RLIMIT_CPU counts the CPU time it has
 * used since its start, so setting it after the spawn loses nothing. Its
 * soft limit's SIGXCPU would dump core: no core. The nice value is its main
 * thread's, where `parse --mode serial` does its work. */
static void bound_child(pid_t pid)
{
    struct rlimit cpu = { PREVIEW_CPU_S, PREVIEW_CPU_S + 1 }, core = { 0, 0 };
    (void)prlimit(pid, RLIMIT_CORE, &core, NULL);
    (void)prlimit(pid, RLIMIT_CPU, &cpu, NULL);
    (void)setpriority(PRIO_PROCESS, (id_t)pid, PREVIEW_NICE);
}

/* `self parse TEXT --mode serial --canon -`'s output (stdout and stderr)
 * into out: 0, or -1 with why. */
static int run_parse(const char *self, const struct ncp_http_prog *prog, const atomic_int *stop,
                     struct buf *out, char *why, size_t wl)
{
    int fds[2] = { -1, -1 };
    int text = text_file(prog);
    if (text < 0 || pipe2(fds, O_CLOEXEC)) {
        snprintf(why, wl, "preview: %s", strerror(errno));
        if (text >= 0)
            close(text);
        return -1;
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, text, 3);
    posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
    posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
    char *argv[] = { (char *)self, "parse", "/dev/fd/3", "--mode", "serial",
                     "--canon", "-", NULL };
    pid_t pid;
    int rc = posix_spawn(&pid, self, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(fds[1]);
    close(text);
    if (rc) {
        close(fds[0]);
        return snprintf(why, wl, "preview: cannot run %s: %s", self, strerror(rc)), -1;
    }
    bound_child(pid);
    int64_t deadline = ncp_mono_ms() + PREVIEW_TIMEOUT_MS;
    int fail = 0;
    for (;;) {
        int64_t left = deadline - ncp_mono_ms();
        if (atomic_load(stop)) {
            fail = snprintf(why, wl, "preview: the panel is shutting down");
            break;
        }
        if (left <= 0) {
            fail = snprintf(why, wl, "preview: the interpreter took over %d s",
                            PREVIEW_TIMEOUT_MS / 1000);
            break;
        }
        struct pollfd p = { fds[0], POLLIN, 0 };
        int n = poll(&p, 1, left < 100 ? (int)left : 100);
        if (n < 0 && errno != EINTR) {
            fail = snprintf(why, wl, "preview: %s", strerror(errno));
            break;
        }
        if (n <= 0)
            continue;
        if (out->len >= CANON_MAX) {
            fail = snprintf(why, wl, "preview: more than %u MB of commands", CANON_MAX >> 20);
            break;
        }
        if (buf_reserve(out, 65536)) {
            fail = snprintf(why, wl, "preview: out of memory");
            break;
        }
        ssize_t r = read(fds[0], out->p + out->len, 65536);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        out->len += (size_t)r;
    }
    close(fds[0]);
    if (fail)
        kill(pid, SIGKILL);
    int st = 0;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
    if (!fail && WIFSIGNALED(st) && WTERMSIG(st) == SIGXCPU)
        fail = snprintf(why, wl, "preview: the interpreter used over %d s of CPU", PREVIEW_CPU_S);
    return fail ? -1 : 0;
}

static int preview(const char *self, const struct ncp_http_prog *prog, const atomic_int *stop,
                   struct ncp_http_msg *out)
{
    if (!prog)
        return refusal("no program loaded", out);
    char why[320];
    struct buf canon = { 0 };
    if (run_parse(self, prog, stop, &canon, why, sizeof why)) {
        free(canon.p);
        return refusal(why, out);
    }
    const char *text = canon.p ? canon.p : "";
    size_t n = canon.len;
    struct buf b;
    int bad = buf_start(&b);
    if (!bad) {
        bad |= buf_put(&b, "{\"type\": \"preview\", \"path\": ");
        bad |= buf_json(&b, prog->path, strlen(prog->path));
        bad |= buf_put(&b, ", \"canon\": ");
        bad |= buf_json(&b, text, n);
        bad |= buf_put(&b, "}");
    }
    free(canon.p);
    return finish(&b, bad, out);
}

int ncp_http_build_answer(const struct ncp_http_paths *paths, const struct ncp_http_prog *prog,
                          enum ncp_http_req r, const atomic_int *stop, struct ncp_http_msg *out)
{
    if (r == NCP_HTTP_REQ_TOOLS || r == NCP_HTTP_REQ_HISTORY)
        return ncp_http_file_answer(paths, r, out);
    if (r == NCP_HTTP_REQ_LIST)
        return list(paths->program_dir, out);
    if (r == NCP_HTTP_REQ_PROGRAM)
        return program(prog, out);
    return preview(paths->self_exe, prog, stop, out);
}
