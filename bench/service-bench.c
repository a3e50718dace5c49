/* The serving NCK's messaging, measured from a client (bench/bench-service
 * runs it against `cnc-run serve` in a network namespace):
 *   status  SECONDS   count <prefix>STATUS messages for that long: rate in Hz
 *   acks    N         N commands one after another (a feed override of 100 %,
 *                     accepted in every state): command-to-ACK latency
 *   final             the next STATUS: the position loop's cycles, deadline
 *                     misses and worst latency so far
 * Prints one line of key=value pairs. Links liblcm, as any client would. */
#include <lcm/lcm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ncp_ack_t.h"
#include "ncp_command_t.h"
#include "ncp_status_t.h"

struct bench {
    lcm_t *lcm;
    char prefix[64];
    int statuses;
    ncp_status_t last;
    int32_t client, want_seq;
    int acked;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    struct bench *b = user;
    if (ncp_status_t_decode(rb->data, 0, (int)rb->data_size, &b->last) >= 0)
        b->statuses++;
}

static void on_ack(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    struct bench *b = user;
    ncp_ack_t a;
    if (ncp_ack_t_decode(rb->data, 0, (int)rb->data_size, &a) >= 0 && a.client_id == b->client &&
        a.seq == b->want_seq)
        b->acked = 1;
}

static void handle_for(struct bench *b, double seconds)
{
    double end = now_s() + seconds;
    for (double left; (left = end - now_s()) > 0;)
        lcm_handle_timeout(b->lcm, (int)ceil(left * 1000));
}

static int cmp_double(const void *x, const void *y)
{
    double a = *(const double *)x, c = *(const double *)y;
    return a < c ? -1 : a > c;
}

static int acks(struct bench *b, int n, int quiet)
{
    double *lat = malloc((size_t)n * sizeof *lat);
    if (!lat)
        return 1;
    char ch[96];
    snprintf(ch, sizeof ch, "%sCMD", b->prefix);
    int lost = 0;
    for (int i = 0; i < n; i++) {
        ncp_command_t c;
        memset(&c, 0, sizeof c);
        c.client_id = b->client;
        c.seq = ++b->want_seq;
        c.kind = NCP_COMMAND_T_OVERRIDE;
        c.value[0] = 100;
        uint8_t buf[1024];
        int len = ncp_command_t_encode(buf, 0, sizeof buf, &c);
        b->acked = 0;
        double t0 = now_s();
        lcm_publish(b->lcm, ch, buf, (unsigned)len);
        while (!b->acked && now_s() - t0 < 1.0)
            lcm_handle_timeout(b->lcm, 100);
        if (!b->acked) {
            lost++;
            lat[i] = 1.0;
        } else {
            lat[i] = now_s() - t0;
        }
    }
    qsort(lat, (size_t)n, sizeof lat[0], cmp_double);
    double sum = 0;
    for (int i = 0; i < n; i++)
        sum += lat[i];
    if (!quiet)
        printf("acks=%d lost=%d p50_us=%.0f p99_us=%.0f max_us=%.0f mean_us=%.0f\n", n, lost,
           lat[n / 2] * 1e6, lat[(int)(0.99 * (n - 1))] * 1e6, lat[n - 1] * 1e6,
           sum / n * 1e6);
    free(lat);
    return lost != 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: service-bench URL PREFIX status SECONDS | acks N | final\n");
        return 1;
    }
    struct bench b;
    memset(&b, 0, sizeof b);
    b.lcm = lcm_create(argv[1]);
    if (!b.lcm) {
        fprintf(stderr, "service-bench: cannot open LCM at %s\n", argv[1]);
        return 1;
    }
    snprintf(b.prefix, sizeof b.prefix, "%s", argv[2]);
    char ch[96];
    snprintf(ch, sizeof ch, "%sSTATUS", b.prefix);
    lcm_subscribe(b.lcm, ch, on_status, &b);
    snprintf(ch, sizeof ch, "%sACK", b.prefix);
    lcm_subscribe(b.lcm, ch, on_ack, &b);
    b.client = (int32_t)(getpid() | 0x40000000);
    int rc = 0;
    for (int i = 3; i + 1 <= argc - 1 || (i < argc && !strcmp(argv[i], "final")); i += 2) {
        if (!strcmp(argv[i], "status")) {
            double secs = atof(argv[i + 1]);
            handle_for(&b, 0.2);   /* the first message may be mid-period */
            b.statuses = 0;
            double t0 = now_s();
            handle_for(&b, secs);
            printf("status_msgs=%d seconds=%.3f rate_hz=%.2f\n", b.statuses, now_s() - t0,
                   b.statuses / (now_s() - t0));
        } else if (!strcmp(argv[i], "acks")) {
            rc |= acks(&b, atoi(argv[i + 1]), 0);
        } else if (!strcmp(argv[i], "final")) {
            /* a command's ACK is followed by a status, whatever STATUS_HZ says */
            rc |= acks(&b, 1, 1);
            b.statuses = 0;
            while (b.statuses == 0)
                lcm_handle_timeout(b.lcm, 1000);
            printf("cycles=%lld misses=%lld latency_max_us=%.1f state=%d garbage=%lld\n",
                   (long long)b.last.cycles, (long long)b.last.deadline_misses,
                   b.last.latency_max_us, b.last.state, (long long)b.last.garbage);
            i--;
        } else {
            fprintf(stderr, "service-bench: unknown step %s\n", argv[i]);
            rc = 1;
            break;
        }
    }
    lcm_destroy(b.lcm);
    return rc;
}
