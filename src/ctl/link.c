/* cnc-ctl's LCM link: liblcm for the socket work, the generated types for
 * the messages (subscribed raw, decoded here). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>
#include <unistd.h>

#include "ctl.h"
#include "ncpar/auth.h"
#include "ncpar/clock.h"

#define RESEND_S 0.5
#define KEEPALIVE_FRESH_S 0.3  /* a keep-alive holds a jog this long (the NCK's limit) */
#define FRESH_MAX_S 600.0      /* the longest the NCK lets a command stay fresh */
/* The command's deadline lies this much before the moment cnc-ctl gives up
 * (at most): a command the NCK takes just before its deadline has its ACK
 * back before the client reports no answer. */
#define DEADLINE_MARGIN_S 0.1

volatile sig_atomic_t ctl_interrupted;

static void on_signal(int sig)
{
    (void)sig;
    ctl_interrupted = 1;
}

void ctl_catch_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sa.sa_flags = (int)SA_RESETHAND; /* a second ^C ends it at once */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

double ctl_now(void)
{
    return (double)ncp_mono_ns() * 1e-9;
}

static int64_t utime_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* The message's encoding when it carries the key's seal (decrypted where it
 * was encrypted), copied into buf: its length, or -1 (not from the NCK:
 * ignored, as a forged ACK or status must change nothing here either). */
static int sealed_body(struct ctl *c, const lcm_recv_buf_t *rbuf, const char *channel,
                       uint8_t *buf, size_t size)
{
    if (rbuf->data_size > size)
        return -1;
    memcpy(buf, rbuf->data, rbuf->data_size);
    size_t n;
    int64_t sent_ns;
    if (ncp_auth_check(c->auth, channel, buf, rbuf->data_size, &n, &sent_ns) != NCP_AUTH_OK) {
        c->unsealed++;
        return -1;
    }
    return (int)n;
}

static void on_ack(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    struct ctl *c = user;
    ncp_ack_t a;
    uint8_t buf[4096];
    int n = sealed_body(c, rbuf, channel, buf, sizeof buf);
    if (n < 0 || ncp_ack_t_decode(buf, 0, n, &a) != n)
        return;
    if (a.client_id != c->client_id || a.seq != c->want_seq || c->want_seq == 0)
        return;
    c->ack = a;
    c->have_ack = 1;
}

static void on_status(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    struct ctl *c = user;
    ncp_status_t s;
    uint8_t buf[8192];
    int n = sealed_body(c, rbuf, channel, buf, sizeof buf);
    if (n < 0 || ncp_status_t_decode(buf, 0, n, &s) != n)
        return;
    if (s.channel >= 0)
        c->served[s.channel] = 1;
    if (s.channel != c->channel) {
        if (c->other_statuses++ == 0)
            c->first_other_at = ctl_now();
        return;
    }
    c->status = s;
    c->status_at = ctl_now();
    c->n_status++;
}

static void on_event(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    struct ctl *c = user;
    ncp_event_t e;
    uint8_t buf[4096];
    int n = sealed_body(c, rbuf, channel, buf, sizeof buf);
    if (n < 0 || ncp_event_t_decode(buf, 0, n, &e) != n)
        return;
    if (e.channel == c->channel && c->on_event)
        c->on_event(&e, c->event_ctx);
}

static int32_t random_client_id(void)
{
    int32_t id = 0;
    while (id == 0) {
        if (getrandom(&id, sizeof id, 0) != (ssize_t)sizeof id)
            id = (int32_t)((uint32_t)getpid() * 2654435761u ^ (uint32_t)utime_now());
    }
    return id;
}

int ctl_open(struct ctl *c, const char *url, const char *prefix, const char *key_file)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if ((c->auth = ncp_auth_open(key_file, NULL, 0, &d)) == NULL) {
        fprintf(stderr, "cnc-ctl: error: %s\n", d.msg);
        return CTL_USAGE;
    }
    if (strlen(prefix) > NCP_MSG_PREFIX_MAX) {
        fprintf(stderr, "cnc-ctl: the channel prefix '%s' is longer than %d characters\n",
                prefix, NCP_MSG_PREFIX_MAX);
        return CTL_USAGE;
    }
    snprintf(c->ch_cmd, sizeof c->ch_cmd, "%sCMD", prefix);
    snprintf(c->ch_ack, sizeof c->ch_ack, "%sACK", prefix);
    snprintf(c->ch_status, sizeof c->ch_status, "%sSTATUS", prefix);
    snprintf(c->ch_event, sizeof c->ch_event, "%sEVENT", prefix);
    c->url = url;
    c->client_id = random_client_id();
    c->lcm = lcm_create(url);
    if (c->lcm == NULL) {
        fprintf(stderr, "cnc-ctl: cannot open LCM at %s (see docs/operator.md: LCM and multicast)\n",
                url ? url : "the default URL");
        return CTL_USAGE;
    }
    if (lcm_subscribe(c->lcm, c->ch_ack, on_ack, c) == NULL ||
        lcm_subscribe(c->lcm, c->ch_status, on_status, c) == NULL) {
        fprintf(stderr, "cnc-ctl: cannot subscribe to %s and %s\n", c->ch_ack, c->ch_status);
        return CTL_USAGE;
    }
    return CTL_OK;
}

void ctl_close(struct ctl *c)
{
    if (c->lcm)
        lcm_destroy(c->lcm);
    c->lcm = NULL;
    ncp_auth_free(c->auth);
    c->auth = NULL;
}

static int publish(struct ctl *c, const ncp_command_t *cmd)
{
    uint8_t buf[1024 + NCP_AUTH_TRAILER_BYTES];
    int n = ncp_command_t_encode(buf, 0, (int)sizeof buf - (int)NCP_AUTH_TRAILER_BYTES, cmd);
    if (n >= 0)
        n = (int)ncp_auth_seal(c->auth, c->ch_cmd, buf, (size_t)n, 0, ncp_auth_now_ns());
    if (n < 0 || lcm_publish(c->lcm, c->ch_cmd, buf, (unsigned)n) != 0) {
        fprintf(stderr, "cnc-ctl: cannot send on %s (see docs/operator.md: LCM and multicast)\n",
                c->ch_cmd);
        return -1;
    }
    return 0;
}

/* How long the command may still act: a keep-alive its window, any other
 * until just before cnc-ctl gives up waiting for its ACK. */
static double fresh_s(const struct ctl *c, const ncp_command_t *cmd)
{
    if (cmd->kind == NCP_COMMAND_T_KEEPALIVE)
        return KEEPALIVE_FRESH_S;
    if (c->timeout <= 0 || c->timeout > FRESH_MAX_S)
        return FRESH_MAX_S;
    double margin = c->timeout / 10 < DEADLINE_MARGIN_S ? c->timeout / 10 : DEADLINE_MARGIN_S;
    return c->timeout - margin;
}

int ctl_send(struct ctl *c, ncp_command_t *cmd)
{
    cmd->utime = utime_now();
    cmd->deadline_utime = cmd->utime + (int64_t)(fresh_s(c, cmd) * 1e6);
    cmd->client_id = c->client_id;
    cmd->seq = ++c->seq;
    cmd->channel = c->channel;
    return publish(c, cmd);
}

int ctl_handle(struct ctl *c, double seconds)
{
    int ms = seconds <= 0 ? 0 : (int)ceil(seconds * 1000.0);
    int r = lcm_handle_timeout(c->lcm, ms);
    if (r < 0 && errno != EINTR) {
        fprintf(stderr, "cnc-ctl: cannot receive LCM messages (is there a multicast route? "
                        "see docs/operator.md: LCM and multicast)\n");
        return -1;
    }
    return 0;
}

void ctl_no_answer(const char *what, double seconds)
{
    fprintf(stderr,
            "cnc-ctl: no %s from the NCK within %g s (is `cnc-run serve` running, with the "
            "same LCM URL and prefix?)\n",
            what, seconds);
}

int ctl_command(struct ctl *c, ncp_command_t *cmd)
{
    if (ctl_send(c, cmd) != 0)
        return CTL_USAGE;
    c->want_seq = cmd->seq;
    c->have_ack = 0;
    double start = ctl_now(), resend = start + RESEND_S;
    while (!c->have_ack) {
        double now = ctl_now();
        if (c->timeout > 0 && now - start >= c->timeout) {
            ctl_no_answer("answer", c->timeout);
            return CTL_NO_ANSWER;
        }
        if (now >= resend) {
            /* the same seq: the NCK re-acks a duplicate instead of acting twice */
            if (publish(c, cmd) != 0)
                return CTL_USAGE;
            resend = now + RESEND_S;
        }
        double wait = resend - now;
        if (c->timeout > 0 && start + c->timeout - now < wait)
            wait = start + c->timeout - now;
        if (ctl_handle(c, wait) != 0)
            return CTL_USAGE;
    }
    c->want_seq = 0;
    if (c->ack.result == NCP_ACK_T_ACCEPTED)
        return CTL_OK;
    fprintf(stderr, "cnc-ctl: rejected: %.*s\n", (int)strnlen((const char *)c->ack.reason,
                                                              sizeof c->ack.reason),
            (const char *)c->ack.reason);
    return c->ack.state == NCP_STATUS_T_FAULT ? CTL_FAULT : CTL_REJECTED;
}

/* Three statuses of other channels over a second or more, and not one of
 * ours: at any STATUS_HZ ours would have come by then, unless it is not
 * served (a datagram lost on the way is one status, not three). */
static int channel_not_served(const struct ctl *c)
{
    return c->n_status == 0 && c->other_statuses >= 3 && ctl_now() - c->first_other_at >= 1.0;
}

static void say_not_served(const struct ctl *c)
{
    char list[128 * 4] = "";
    size_t len = 0;
    for (int i = 0; i < 128 && len + 5 < sizeof list; i++)
        if (c->served[i])
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%d", len ? ", " : "", i);
    fprintf(stderr, "cnc-ctl: the NCK serves no NC channel %d (it serves %s)\n", c->channel,
            list);
}

int ctl_next_status(struct ctl *c, double timeout)
{
    uint64_t seen = c->n_status;
    double start = ctl_now();
    while (c->n_status == seen) {
        if (ctl_interrupted)
            return -1;
        if (channel_not_served(c)) {
            say_not_served(c);
            return CTL_REJECTED;
        }
        double left = timeout > 0 ? start + timeout - ctl_now() : 0.25;
        if (left <= 0)
            return CTL_NO_ANSWER;
        if (ctl_handle(c, left < 0.25 ? left : 0.25) != 0)
            return CTL_USAGE;
    }
    return CTL_OK;
}

int ctl_follow_events(struct ctl *c, double seconds,
                      void (*show)(const ncp_event_t *e, void *ctx), void *ctx)
{
    c->on_event = show;
    c->event_ctx = ctx;
    if (lcm_subscribe(c->lcm, c->ch_event, on_event, c) == NULL) {
        fprintf(stderr, "cnc-ctl: cannot subscribe to %s\n", c->ch_event);
        return CTL_USAGE;
    }
    double end = ctl_now() + seconds;
    while (!ctl_interrupted) {
        double left = seconds > 0 ? end - ctl_now() : 0.25;
        if (left <= 0)
            break;
        if (ctl_handle(c, left < 0.25 ? left : 0.25) != 0)
            return CTL_USAGE;
    }
    return CTL_OK;
}

int ctl_wait_done(struct ctl *c, int busy_state, const char *what)
{
    int64_t acked_utime = c->ack.utime;
    double last = ctl_now();
    for (;;) {
        int rc = ctl_next_status(c, 0.25);
        if (rc < 0)
            return CTL_NO_ANSWER; /* interrupted: not seen to end */
        double now = ctl_now();
        if (rc == CTL_NO_ANSWER) {
            if (c->timeout > 0 && now - last >= c->timeout) {
                ctl_no_answer("status", c->timeout);
                return CTL_NO_ANSWER;
            }
            continue;
        }
        if (rc != CTL_OK)
            return rc;
        last = now;
        /* a status sent before the ACK may still show the state before the
         * command: only later ones say how it ended */
        if (c->status.utime < acked_utime || c->status.state == busy_state)
            continue;
        if (c->status.state == NCP_STATUS_T_FAULT || c->status.state == NCP_STATUS_T_ESTOP) {
            const char *st = ncp_msg_state_name(c->status.state);
            fprintf(stderr, "cnc-ctl: %s ended in %s: %.*s\n", what, st ? st : "?",
                    (int)strnlen((const char *)c->status.error, sizeof c->status.error),
                    (const char *)c->status.error);
            return CTL_FAULT;
        }
        return CTL_OK;
    }
}
