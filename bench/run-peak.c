/* bench/run-peak CMD [ARG...]: runs CMD and prints, on one line to stderr,
 * what it cost: wall seconds, user and system CPU seconds, peak RSS (the
 * kernel's, from wait4), the highest anonymous and file-backed RSS seen
 * (RssAnon and RssFile of /proc/PID/status, read every 2 ms: a mapped
 * program's pages count as file RSS, the process's own memory as anonymous),
 * minor and major page faults, and CMD's exit status:
 *
 *   run-peak: wall 1.234 user 1.100 sys 0.050 maxrss_kb 40000 anon_kb 3500 file_kb 15000 minflt 900 majflt 0 status 0
 *
 * CMD's own output goes where run-peak's goes. bench/scale uses it. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec / 1e9;
}

/* The value of `key` (e.g. "RssAnon:") in a /proc status text, or -1. */
static long field_kb(const char *text, const char *key)
{
    const char *at = strstr(text, key);
    return at ? strtol(at + strlen(key), NULL, 10) : -1;
}

static void sample(int fd, long *anon, long *file)
{
    char buf[4096];
    ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
    if (n <= 0)
        return;
    buf[n] = '\0';
    long a = field_kb(buf, "RssAnon:"), f = field_kb(buf, "RssFile:");
    if (a > *anon)
        *anon = a;
    if (f > *file)
        *file = f;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: run-peak CMD [ARG...]\n");
        return 1;
    }
    double t0 = now_s();
    pid_t pid = fork();
    if (pid < 0) {
        perror("run-peak: fork");
        return 1;
    }
    if (pid == 0) {
        execvp(argv[1], argv + 1);
        fprintf(stderr, "run-peak: cannot run %s: %s\n", argv[1], strerror(errno));
        _exit(127);
    }
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    long anon = 0, file = 0;
    int status = 0;
    struct rusage ru;
    const struct timespec period = { 0, 2000000 };
    for (;;) {
        pid_t w = wait4(pid, &status, WNOHANG, &ru);
        if (w == pid)
            break;
        if (w < 0 && errno != EINTR) {
            perror("run-peak: wait4");
            return 1;
        }
        if (fd >= 0)
            sample(fd, &anon, &file);
        nanosleep(&period, NULL);
    }
    double wall = now_s() - t0;
    if (fd >= 0)
        close(fd);
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    fprintf(stderr,
            "run-peak: wall %.3f user %.3f sys %.3f maxrss_kb %ld anon_kb %ld file_kb %ld "
            "minflt %ld majflt %ld status %d\n",
            wall, (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec / 1e6,
            (double)ru.ru_stime.tv_sec + (double)ru.ru_stime.tv_usec / 1e6, ru.ru_maxrss, anon,
            file, ru.ru_minflt, ru.ru_majflt, code);
    return code;
}
