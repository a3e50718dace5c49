/* The panel's HTTP and WebSocket server on libwebsockets' own thread.
 *
 * Two threads meet here, under one mutex, never holding it across I/O:
 *   the serving thread (ncp_nck_serve's hook) copies each STATUS, ACK and
 *   EVENT in and takes the queued commands out, then wakes this thread with
 *   lws_cancel_service();
 *   this thread (lws_service) turns them into JSON for the sockets, and the
 *   sockets' messages into commands for the queue.
 * A full queue refuses (counted) rather than waits: neither thread blocks
 * the other, and the NCK's real-time threads never see any of it. */
#include "server_int.h"

#include <libwebsockets.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

#define CMD_QUEUE 64            /* commands waiting for the serving thread */
#define NOTE_QUEUE 64           /* acks and events waiting for this thread */
#define OUT_QUEUE 64            /* messages waiting for one socket */
#define MAX_CONNS 16
#define RATE_PER_S 50.0         /* commands per socket: a continuous jog's keep-alive */
#define RATE_BURST 100.0        /* is 10/s, a person's clicking far less */

struct outmsg {
    unsigned char *buf;         /* LWS_PRE bytes, then the message */
    size_t len;
};

struct conn {
    struct lws *wsi;
    struct conn *next;
    int authed;
    int32_t client_id;
    char rx[NCP_HTTP_MSG_MAX + 1];
    size_t rx_len;
    int rx_over;
    struct outmsg out[OUT_QUEUE];
    unsigned out_head, out_n;
    int64_t status_sent;        /* seq of the last status written */
    double bucket;
    int64_t bucket_ns;
};

struct ncp_http {
    struct ncp_http_opts o;
    char token[NCP_HTTP_TOKEN_LEN + 1];
    struct ncp_nck_serve_hook hook;
    struct lws_context *ctx;
    struct lws_http_mount mount, upload_mount;
    struct lws_protocols protocols[4];
    pthread_t thread;
    atomic_int stop;
    int32_t next_client;

    pthread_mutex_t mu;         /* guards what the two threads share: */
    ncp_command_t cmds[CMD_QUEUE];
    unsigned cmd_head, cmd_n;
    ncp_status_t status;
    int64_t status_seq;         /* 0: none yet */
    ncp_ack_t acks[NOTE_QUEUE];
    unsigned ack_head, ack_n;
    ncp_event_t events[NOTE_QUEUE];
    unsigned ev_head, ev_n;
    struct ncp_http_stats stats;

    /* this thread's own */
    struct conn *conns;
    int n_conns;
    unsigned char *status_msg;  /* LWS_PRE + the newest status as JSON */
    size_t status_len;
    int64_t status_msg_seq;
};

static int64_t mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

static void count(struct ncp_http *h, uint64_t *field)
{
    pthread_mutex_lock(&h->mu);
    (*field)++;
    pthread_mutex_unlock(&h->mu);
}

void ncp_http_count(struct ncp_http *h, enum ncp_http_stat which)
{
    struct ncp_http_stats *st = &h->stats;
    uint64_t *field = which == NCP_HTTP_STAT_NO_TOKEN ? &st->no_token
                    : which == NCP_HTTP_STAT_READONLY ? &st->readonly
                    : which == NCP_HTTP_STAT_OVERSIZED ? &st->oversized
                    : which == NCP_HTTP_STAT_UPLOADS ? &st->uploads : &st->upload_bad;
    count(h, field);
}

/* ---- the serving thread's side (the hook) ------------------------------------------ */

static int hook_next_command(void *ctx, ncp_command_t *c)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->mu);
    int got = h->cmd_n > 0;
    if (got) {
        *c = h->cmds[h->cmd_head];
        h->cmd_head = (h->cmd_head + 1) % CMD_QUEUE;
        h->cmd_n--;
    }
    pthread_mutex_unlock(&h->mu);
    return got;
}

static void hook_ack(void *ctx, const ncp_ack_t *a)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->mu);
    /* only the panel's own clients get acks; the oldest goes when full */
    int ours = (a->client_id & NCP_HTTP_CLIENT_MASK) == NCP_HTTP_CLIENT_TAG;
    if (ours) {
        if (h->ack_n == NOTE_QUEUE) {
            h->ack_head = (h->ack_head + 1) % NOTE_QUEUE;
            h->ack_n--;
        }
        h->acks[(h->ack_head + h->ack_n++) % NOTE_QUEUE] = *a;
    }
    pthread_mutex_unlock(&h->mu);
    if (ours)
        lws_cancel_service(h->ctx);
}

static void hook_status(void *ctx, const ncp_status_t *s)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->mu);
    h->status = *s;
    h->status_seq = s->seq;
    pthread_mutex_unlock(&h->mu);
    lws_cancel_service(h->ctx);
}

static void hook_event(void *ctx, const ncp_event_t *e)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->mu);
    if (h->ev_n == NOTE_QUEUE) {
        h->ev_head = (h->ev_head + 1) % NOTE_QUEUE;
        h->ev_n--;
    }
    h->events[(h->ev_head + h->ev_n++) % NOTE_QUEUE] = *e;
    pthread_mutex_unlock(&h->mu);
    lws_cancel_service(h->ctx);
}

/* ---- this thread: sockets ----------------------------------------------------------- */

/* Queues msg[len] (copied) for c; the oldest waiting message goes when full. */
void ncp_http_send(struct ncp_http *h, struct conn *c, const char *msg, size_t len)
{
    unsigned char *b = malloc(LWS_PRE + len);
    if (!b)
        return;
    memcpy(b + LWS_PRE, msg, len);
    if (c->out_n == OUT_QUEUE) {
        free(c->out[c->out_head].buf);
        c->out_head = (c->out_head + 1) % OUT_QUEUE;
        c->out_n--;
        count(h, &h->stats.dropped);
    }
    c->out[(c->out_head + c->out_n++) % OUT_QUEUE] = (struct outmsg){ b, len };
    lws_callback_on_writable(c->wsi);
}

void ncp_http_refuse(struct ncp_http *h, struct conn *c, int32_t seq, const char *why)
{
    char msg[512];
    size_t n = (size_t)snprintf(msg, sizeof msg, "{\"type\": \"refused\", \"seq\": %d, \"reason\": ",
                                (int)seq);
    ncp_http_json_string(msg, sizeof msg - 2, &n, why, strlen(why));
    msg[n++] = '}';
    ncp_http_send(h, c, msg, n);
}

static void render_status(struct ncp_http *h)
{
    pthread_mutex_lock(&h->mu);
    if (h->status_seq == h->status_msg_seq) {
        pthread_mutex_unlock(&h->mu);
        return;
    }
    ncp_status_t s = h->status;
    struct ncp_http_stats st = h->stats;
    h->status_msg_seq = h->status_seq;
    pthread_mutex_unlock(&h->mu);
    char *p = (char *)h->status_msg + LWS_PRE;
    size_t size = NCP_HTTP_STATUS_MAX;
    int n = snprintf(p, size, "{\"type\": \"status\", \"utime\": %lld, \"status\": ",
                     (long long)s.utime);
    int k = ncp_msg_status_json(&s, p + n, size - (size_t)n);
    if (k < 0)
        return;
    n += k;
    n += snprintf(p + n, size - (size_t)n,
                  ", \"http\": {\"connections\": %llu, \"commands\": %llu, \"bad_json\": %llu, "
                  "\"unknown\": %llu, \"oversized\": %llu, \"flood\": %llu, \"no_token\": "
                  "%llu, \"readonly\": %llu, \"busy\": %llu, \"dropped\": %llu, "
                  "\"uploads\": %llu, \"upload_bad\": %llu}}",
                  (unsigned long long)st.connections, (unsigned long long)st.commands,
                  (unsigned long long)st.bad_json, (unsigned long long)st.unknown,
                  (unsigned long long)st.oversized, (unsigned long long)st.flood,
                  (unsigned long long)st.no_token, (unsigned long long)st.readonly,
                  (unsigned long long)st.busy, (unsigned long long)st.dropped,
                  (unsigned long long)st.uploads, (unsigned long long)st.upload_bad);
    h->status_len = (size_t)n < size ? (size_t)n : 0;
}

static void render_ack(struct ncp_http *h, const ncp_ack_t *a)
{
    for (struct conn *c = h->conns; c; c = c->next) {
        if (c->client_id != a->client_id)
            continue;
        char msg[512];
        const char *state = ncp_msg_state_name(a->state);
        size_t n = (size_t)snprintf(msg, sizeof msg,
                                    "{\"type\": \"ack\", \"seq\": %d, \"result\": \"%s\", "
                                    "\"state\": \"%s\", \"reason\": ",
                                    (int)a->seq, a->result == NCP_ACK_T_ACCEPTED ? "accepted"
                                                                                 : "rejected",
                                    state ? state : "");
        const char *why = (const char *)a->reason;
        ncp_http_json_string(msg, sizeof msg - 2, &n, why, strnlen(why, sizeof a->reason));
        msg[n++] = '}';
        ncp_http_send(h, c, msg, n);
    }
}

static void render_event(struct ncp_http *h, const ncp_event_t *e)
{
    static const char *const kinds[] = { "info", "msg", "debug", "print", "error", "fault" };
    char msg[2048];
    const char *kind = e->kind >= 0 && e->kind <= 5 ? kinds[e->kind] : "info";
    size_t n = (size_t)snprintf(msg, sizeof msg, "{\"type\": \"event\", \"kind\": \"%s\", "
                                "\"line\": %d, \"col\": %d, \"file\": ", kind, (int)e->line,
                                (int)e->col);
    ncp_http_json_string(msg, sizeof msg, &n, (const char *)e->file,
                         strnlen((const char *)e->file, sizeof e->file));
    n += (size_t)snprintf(msg + n, sizeof msg - n, ", \"text\": ");
    ncp_http_json_string(msg, sizeof msg - 2, &n, (const char *)e->text,
                         strnlen((const char *)e->text, sizeof e->text));
    msg[n++] = '}';
    for (struct conn *c = h->conns; c; c = c->next)
        ncp_http_send(h, c, msg, n);
}

/* The serving thread left something: acks, events, a newer status. */
static void take_notes(struct ncp_http *h)
{
    for (;;) {
        ncp_ack_t a;
        ncp_event_t e;
        int got_ack = 0, got_ev = 0;
        pthread_mutex_lock(&h->mu);
        if (h->ack_n) {
            a = h->acks[h->ack_head];
            h->ack_head = (h->ack_head + 1) % NOTE_QUEUE;
            h->ack_n--;
            got_ack = 1;
        } else if (h->ev_n) {
            e = h->events[h->ev_head];
            h->ev_head = (h->ev_head + 1) % NOTE_QUEUE;
            h->ev_n--;
            got_ev = 1;
        }
        pthread_mutex_unlock(&h->mu);
        if (got_ack)
            render_ack(h, &a);
        else if (got_ev)
            render_event(h, &e);
        else
            break;
    }
    render_status(h);
    for (struct conn *c = h->conns; c; c = c->next)
        if (c->status_sent != h->status_msg_seq && h->status_len)
            lws_callback_on_writable(c->wsi);
}

static int write_next(struct ncp_http *h, struct conn *c)
{
    if (c->out_n) {
        struct outmsg *m = &c->out[c->out_head];
        int rc = lws_write(c->wsi, m->buf + LWS_PRE, m->len, LWS_WRITE_TEXT);
        free(m->buf);
        c->out_head = (c->out_head + 1) % OUT_QUEUE;
        c->out_n--;
        if (rc < (int)m->len)
            return -1;
    } else if (h->status_len && c->status_sent != h->status_msg_seq) {
        if (c->status_sent && h->status_msg_seq > c->status_sent + 1)
            count(h, &h->stats.status_skipped);
        c->status_sent = h->status_msg_seq;
        if (lws_write(c->wsi, h->status_msg + LWS_PRE, h->status_len, LWS_WRITE_TEXT) <
            (int)h->status_len)
            return -1;
        count(h, &h->stats.status_sent);
    }
    if (c->out_n || (h->status_len && c->status_sent != h->status_msg_seq))
        lws_callback_on_writable(c->wsi);
    return 0;
}

/* A socket's command, if its rate allows, into the serving thread's queue. */
static void submit(struct ncp_http *h, struct conn *c, const ncp_command_t *cmd)
{
    if (!c->authed) {
        count(h, &h->stats.no_token);
        ncp_http_refuse(h, c, cmd->seq, "no valid token: this panel may only watch");
        return;
    }
    if (h->o.readonly) {
        count(h, &h->stats.readonly);
        ncp_http_refuse(h, c, cmd->seq, "the panel is read-only (--http-readonly)");
        return;
    }
    pthread_mutex_lock(&h->mu);
    int full = h->cmd_n == CMD_QUEUE;
    if (full) {
        h->stats.busy++;
    } else {
        h->cmds[(h->cmd_head + h->cmd_n++) % CMD_QUEUE] = *cmd;
        h->stats.commands++;
    }
    pthread_mutex_unlock(&h->mu);
    if (full)
        ncp_http_refuse(h, c, cmd->seq, "the NCK is busy: command not taken");
}

/* Token bucket per socket: 0 when this message may be taken. */
static int over_rate(struct conn *c)
{
    int64_t now = mono_ns();
    c->bucket += (double)(now - c->bucket_ns) * 1e-9 * RATE_PER_S;
    if (c->bucket > RATE_BURST)
        c->bucket = RATE_BURST;
    c->bucket_ns = now;
    if (c->bucket < 1.0)
        return 1;
    c->bucket -= 1.0;
    return 0;
}

static void on_message(struct ncp_http *h, struct conn *c)
{
    if (c->rx_over) {
        count(h, &h->stats.oversized);
        ncp_http_refuse(h, c, 0, "message too large");
        return;
    }
    if (over_rate(c)) {
        /* no answer: answering a flood would be one more */
        count(h, &h->stats.flood);
        return;
    }
    ncp_command_t cmd;
    int unknown;
    char why[128];
    enum ncp_http_req r =
        ncp_http_parse_request(c->rx, c->rx_len, c->client_id, &cmd, &unknown, why, sizeof why);
    switch (r) {
    case NCP_HTTP_REQ_COMMAND:
        submit(h, c, &cmd);
        break;
    case NCP_HTTP_REQ_BAD:
        count(h, unknown ? &h->stats.unknown : &h->stats.bad_json);
        ncp_http_refuse(h, c, 0, why);
        break;
    default:
        if (!c->authed) {
            count(h, &h->stats.no_token);
            ncp_http_refuse(h, c, 0, "no valid token: this panel may only watch");
            break;
        }
        pthread_mutex_lock(&h->mu);
        char program[sizeof h->status.program + 1];
        snprintf(program, sizeof program, "%s", (const char *)h->status.program);
        pthread_mutex_unlock(&h->mu);
        ncp_http_answer_query(h, c, r, program);
        break;
    }
}

int ncp_http_token_ok(const struct ncp_http *h, struct lws *wsi)
{
    char buf[128];
    const char *t = lws_get_urlarg_by_name(wsi, "token=", buf, (int)sizeof buf);
    if (!t || strlen(t) != NCP_HTTP_TOKEN_LEN)
        return 0;
    unsigned diff = 0;   /* the same time for every wrong token */
    for (int i = 0; i < NCP_HTTP_TOKEN_LEN; i++)
        diff |= (unsigned)(t[i] ^ h->token[i]);
    return diff == 0;
}

static void drop_conn(struct ncp_http *h, struct conn *c)
{
    for (struct conn **p = &h->conns; *p; p = &(*p)->next)
        if (*p == c) {
            *p = c->next;
            h->n_conns--;
            break;
        }
    while (c->out_n) {
        free(c->out[c->out_head].buf);
        c->out_head = (c->out_head + 1) % OUT_QUEUE;
        c->out_n--;
    }
}

static int on_ws(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                 size_t len)
{
    struct ncp_http *h = lws_context_user(lws_get_context(wsi));
    struct conn *c = user;
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
        return h->n_conns >= MAX_CONNS;
    case LWS_CALLBACK_ESTABLISHED:
        /* the session's memory is new here; the URL's query still readable */
        memset(c, 0, sizeof *c);
        c->authed = ncp_http_token_ok(h, wsi);
        c->wsi = wsi;
        c->client_id = NCP_HTTP_CLIENT_TAG | (h->next_client++ & ~NCP_HTTP_CLIENT_MASK);
        c->bucket = RATE_BURST;
        c->bucket_ns = mono_ns();
        c->next = h->conns;
        h->conns = c;
        h->n_conns++;
        count(h, &h->stats.connections);
        {
            char hello[160];
            int n = snprintf(hello, sizeof hello,
                             "{\"type\": \"hello\", \"authed\": %s, \"readonly\": %s}",
                             c->authed ? "true" : "false", h->o.readonly ? "true" : "false");
            ncp_http_send(h, c, hello, (size_t)n);
        }
        break;
    case LWS_CALLBACK_CLOSED:
        drop_conn(h, c);
        break;
    case LWS_CALLBACK_RECEIVE:
        if (lws_is_first_fragment(wsi)) {
            c->rx_len = 0;
            c->rx_over = 0;
        }
        if (c->rx_len + len > NCP_HTTP_MSG_MAX)
            c->rx_over = 1;
        else {
            memcpy(c->rx + c->rx_len, in, len);
            c->rx_len += len;
        }
        if (lws_is_final_fragment(wsi) && !lws_remaining_packet_payload(wsi)) {
            c->rx[c->rx_len] = 0;
            on_message(h, c);
        }
        break;
    case LWS_CALLBACK_SERVER_WRITEABLE:
        return write_next(h, c);
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        take_notes(h);
        break;
    default:
        break;
    }
    return 0;
}

static void *serve_loop(void *arg)
{
    struct ncp_http *h = arg;
    while (!atomic_load(&h->stop))
        if (lws_service(h->ctx, 0) < 0)
            break;
    return NULL;
}

int ncp_http_available(void)
{
    return 1;
}

static int make_token(char *out)
{
    unsigned char r[NCP_HTTP_TOKEN_LEN / 2];
    if (getrandom(r, sizeof r, 0) != (ssize_t)sizeof r)
        return -1;
    for (size_t i = 0; i < sizeof r; i++)
        sprintf(out + 2 * i, "%02x", r[i]);
    return 0;
}

struct ncp_http *ncp_http_start(const struct ncp_http_opts *o, struct ncp_diag *d)
{
    struct ncp_http *h = calloc(1, sizeof *h);
    if (h)
        h->status_msg = malloc(LWS_PRE + NCP_HTTP_STATUS_MAX);
    if (!h || !h->status_msg) {
        free(h);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
        return NULL;
    }
    h->o = *o;
    if (make_token(h->token)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: no random numbers for the token");
        goto fail;
    }
    h->next_client = (int32_t)(h->token[0] * 4099 + h->token[1]);
    pthread_mutex_init(&h->mu, NULL);
    h->hook = (struct ncp_nck_serve_hook){ hook_next_command, hook_ack, hook_status,
                                           hook_event, h };
    h->mount = (struct lws_http_mount){ .mountpoint = "/", .origin = h->o.web_root,
                                        .def = "index.html",
                                        .origin_protocol = LWSMPRO_FILE, .mountpoint_len = 1 };
    h->protocols[0] = (struct lws_protocols){ "http", lws_callback_http_dummy, 0, 0, 0, NULL, 0 };
    h->protocols[1] = (struct lws_protocols){ "ncp-panel", on_ws, sizeof(struct conn),
                                              NCP_HTTP_MSG_MAX, 0, NULL, 0 };
    h->protocols[2] = (struct lws_protocols){ "ncp-upload", ncp_http_on_upload,
                                              ncp_http_upload_session_size(), 0, 0, NULL, 0 };
    h->upload_mount = (struct lws_http_mount){ .mountpoint = "/upload", .origin = "ncp-upload",
                                               .origin_protocol = LWSMPRO_CALLBACK,
                                               .mountpoint_len = 7 };
    h->mount.mount_next = &h->upload_mount;
    lws_set_log_level(LLL_ERR, NULL);
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = o->port;
    info.iface = h->o.addr;
    info.protocols = h->protocols;
    info.mounts = &h->mount;
    info.user = h;
    info.options = LWS_SERVER_OPTION_VALIDATE_UTF8;
    if (!strchr(h->o.addr, ':'))
        info.options |= LWS_SERVER_OPTION_DISABLE_IPV6;
    h->ctx = lws_create_context(&info);
    if (!h->ctx) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: cannot listen on %s port %d (in use?)",
                     o->addr, o->port);
        goto fail;
    }
    /* signals stay with the main thread, which turns them into a stop */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    int rc = pthread_create(&h->thread, NULL, serve_loop, h);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (rc) {
        lws_context_destroy(h->ctx);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: cannot start its thread");
        goto fail;
    }
    return h;
fail:
    free(h->status_msg);
    free(h);
    return NULL;
}

void ncp_http_stop(struct ncp_http *h)
{
    if (!h)
        return;
    atomic_store(&h->stop, 1);
    lws_cancel_service(h->ctx);
    pthread_join(h->thread, NULL);
    lws_context_destroy(h->ctx);   /* closes the sockets: CLOSED frees their queues */
    pthread_mutex_destroy(&h->mu);
    free(h->status_msg);
    free(h);
}

const char *ncp_http_token(const struct ncp_http *h)
{
    return h->token;
}

const struct ncp_nck_serve_hook *ncp_http_hook(struct ncp_http *h)
{
    return &h->hook;
}

void ncp_http_get_stats(struct ncp_http *h, struct ncp_http_stats *st)
{
    pthread_mutex_lock(&h->mu);
    *st = h->stats;
    pthread_mutex_unlock(&h->mu);
}

const struct ncp_http_opts *ncp_http_opts_of(const struct ncp_http *h)
{
    return &h->o;
}
