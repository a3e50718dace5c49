/* The serving NCK's messaging, measured from a client (bench/bench-service
 * runs it against `cnc-run serve` in a network namespace):
 *   status  SECONDS   count <prefix>STATUS messages for that long: rate in Hz
 *   acks    N         N commands one after another (a feed override of 100 %,
 *                     accepted in every state): command-to-ACK latency
 *   final             the next STATUS: the position loop's cycles, deadline
 *                     misses and worst latency so far
 *   mac N             (no NCK needed) N seals and N checks of a command, a
 *                     status and a fine-setpoint record: ns per message,
 *                     what the key costs a sender and a receiver
 * Prints one line of key=value pairs. Links liblcm, as any client would, and
 * seals its commands with the NCK's key ($NCP_KEY_FILE, else the default). */
#include <lcm/lcm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ncp_ack_t.h"
#include "ncp_command_t.h"
#include "ncp_fine_ipo_t.h"
#include "ncp_status_t.h"
#include "ncpar/auth.h"

struct bench {
    lcm_t *lcm;
    struct ncp_auth *auth;
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

/* The message's encoding when sealed with the key (copied to buf): length, or -1. */
static int opened(const struct bench *b, const lcm_recv_buf_t *rb, const char *ch, uint8_t *buf,
                  size_t size)
{
    size_t n;
    int64_t sent;
    if (rb->data_size > size)
        return -1;
    memcpy(buf, rb->data, rb->data_size);
    return ncp_auth_check(b->auth, ch, buf, rb->data_size, &n, &sent) == NCP_AUTH_OK ? (int)n
                                                                                      : -1;
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    struct bench *b = user;
    uint8_t buf[8192];
    int n = opened(b, rb, ch, buf, sizeof buf);
    if (n >= 0 && ncp_status_t_decode(buf, 0, n, &b->last) >= 0)
        b->statuses++;
}

static void on_ack(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    struct bench *b = user;
    ncp_ack_t a;
    uint8_t buf[4096];
    int n = opened(b, rb, ch, buf, sizeof buf);
    if (n >= 0 && ncp_ack_t_decode(buf, 0, n, &a) >= 0 && a.client_id == b->client &&
        a.seq == b->want_seq)
        b->acked = 1;
}

/* ns per seal and per check of one encoded message of len bytes. */
static void time_mac(struct ncp_auth *a, const char *what, const char *ch, size_t len, int n)
{
    uint8_t buf[8192];
    memset(buf, 0x5a, sizeof buf);
    double t0 = now_s();
    size_t sealed = 0;
    for (int i = 0; i < n; i++)
        sealed = ncp_auth_seal(a, ch, buf, len, 0, (int64_t)i);
    double t1 = now_s();
    size_t body;
    int64_t sent;
    int bad = 0;
    for (int i = 0; i < n; i++)
        bad += ncp_auth_check(a, ch, buf, sealed, &body, &sent) != NCP_AUTH_OK;
    double t2 = now_s();
    printf("mac %s bytes=%zu seal_ns=%.0f check_ns=%.0f%s\n", what, len, (t1 - t0) / n * 1e9,
           (t2 - t1) / n * 1e9, bad ? " CHECK-FAILED" : "");
}

static int mac_costs(struct ncp_auth *a, int n)
{
    ncp_command_t c;
    ncp_status_t s;
    ncp_fine_ipo_t f;
    memset(&c, 0, sizeof c);
    memset(&s, 0, sizeof s);
    memset(&f, 0, sizeof f);
    time_mac(a, "command", "NCP_CMD", (size_t)ncp_command_t_encoded_size(&c), n);
    time_mac(a, "status", "NCP_STATUS", (size_t)ncp_status_t_encoded_size(&s), n);
    time_mac(a, "fine_setpoint", "NCP_HLC_FINE", (size_t)ncp_fine_ipo_t_encoded_size(&f), n);
    return 0;
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
        uint8_t buf[1024 + NCP_AUTH_TRAILER_BYTES];
        b->acked = 0;
        double t0 = now_s();
        /* the seal and the deadline are part of what a command costs: timed */
        struct timespec rt;
        clock_gettime(CLOCK_REALTIME, &rt);
        c.utime = (int64_t)rt.tv_sec * 1000000 + rt.tv_nsec / 1000;
        c.deadline_utime = c.utime + 1000000;
        int len = ncp_command_t_encode(buf, 0, 1024, &c);
        len = (int)ncp_auth_seal(b->auth, ch, buf, (size_t)len, 0, ncp_auth_now_ns());
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
        fprintf(stderr, "usage: service-bench URL PREFIX status SECONDS | acks N | final | mac N\n");
        return 1;
    }
    struct bench b;
    memset(&b, 0, sizeof b);
    struct ncp_diag d;
    if (!(b.auth = ncp_auth_open(getenv("NCP_KEY_FILE"), NULL, 0, &d))) {
        fprintf(stderr, "service-bench: %s\n", d.msg);
        return 1;
    }
    if (!strcmp(argv[3], "mac"))
        return argc > 4 ? mac_costs(b.auth, atoi(argv[4])) : 1;
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
    ncp_auth_free(b.auth);
    return rc;
}
