/* bench/text-load FILE [N]: what it costs to bring a program's text in, N times
 * each way, interleaved: mapped (MAP_POPULATE) and read with one byte of every
 * page touched and unmapped, as the feeder did before; read() onto memory from
 * ncp_mem_reserve_huge (2 MB pages where THP is offered), touched and unmapped,
 * as it does now. Prints each way's times sorted (ms). bench/RESULTS.md,
 * "Program text on huge pages". */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "ncpar/mem.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static volatile char sink;

static void touch(const char *p, size_t n)
{
    for (size_t off = 0; off < n; off += 4096)
        sink = (char)(sink + p[off]);
}

static double mapped(int fd, size_t n)
{
    double t0 = now_ms();
    char *p = mmap(NULL, n, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (p == MAP_FAILED)
        return -1;
    touch(p, n);
    munmap(p, n);
    return now_ms() - t0;
}

static double copied(int fd, size_t n)
{
    double t0 = now_ms();
    struct ncp_mem m;
    if (ncp_mem_reserve_huge(&m, n) != 0)
        return -1;
    size_t got = 0;
    ssize_t r;
    while (got < n && (r = pread(fd, (char *)m.p + got, n - got, (off_t)got)) > 0)
        got += (size_t)r;
    touch(m.p, got);
    ncp_mem_unmap(&m);
    return now_ms() - t0;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void print(const char *what, double *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp);
    printf("%s (median %.1f ms):", what, t[n / 2]);
    for (int i = 0; i < n; i++)
        printf(" %.1f", t[i]);
    printf("\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: text-load FILE [N]\n");
        return 2;
    }
    int n = argc > 2 ? atoi(argv[2]) : 25;
    if (n < 1 || n > 1000)
        n = 25;
    int fd = open(argv[1], O_RDONLY);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || st.st_size <= 0) {
        perror(argv[1]);
        return 2;
    }
    double *a = calloc((size_t)n, sizeof *a), *b = calloc((size_t)n, sizeof *b);
    if (!a || !b) {
        free(a);
        free(b);
        close(fd);
        return 2;
    }
    for (int i = 0; i < n; i++) {
        a[i] = mapped(fd, (size_t)st.st_size);
        b[i] = copied(fd, (size_t)st.st_size);
    }
    printf("huge pages for advised memory: %s\n", ncp_mem_huge_usable() ? "yes" : "no");
    print("mapped + touched", a, n);
    print("read onto huge pages + touched", b, n);
    free(a);
    free(b);
    close(fd);
    return 0;
}
