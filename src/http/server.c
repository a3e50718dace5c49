/* The panel's HTTP and WebSocket server on libwebsockets' own thread.
 *
 * Three threads meet here, under one mutex, never holding it across I/O:
 *   the serving thread (ncp_nck_serve's hook) copies each STATUS, ACK and
 *   EVENT in and takes the queued commands out, then wakes this thread with
 *   lws_cancel_service();
 *   this thread (lws_service) turns them into JSON for the sockets, and the
 *   sockets' messages into commands for the queue;
 *   the worker (jobs.c) answers the slow queries, so that nothing this
 *   thread does takes long: an E-stop read from a socket is in the serving
 *   thread's queue at once, ahead of every other command.
 * A full queue refuses (counted) rather than waits: neither thread blocks
 * the other, and the NCK's real-time threads never see any of it.
 *
 * Slots: MAX_CONNS sockets for operators (opened with the token), and apart
 * from them a small pool of UNAUTH_MAX sockets without it, each closed
 * UNAUTH_MS after it opened; when the pool is full the oldest goes to make
 * room. Sockets that never authenticate thus cannot keep an operator out,
 * however many are opened: an operator with the token gets in while fewer
 * than MAX_CONNS operators are connected, and a watcher without it still
 * sees the status for a moment (and is told it has no token). */
#include "server_int.h"
#include "ncpar/clock.h"

#include <errno.h>
#include <libwebsockets.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>

#define CMD_QUEUE 64            /* commands waiting for the serving thread */
#define NOTE_QUEUE 64           /* acks and events waiting for this thread */
#define OUT_QUEUE 64            /* messages waiting for one socket */
#define ESTOP_QUEUE 16          /* E-stops: ahead of every other command */
#define MAX_CONNS 16            /* operators' sockets */
#define UNAUTH_MAX 4            /* sockets without the token, */
#define UNAUTH_MS 2000          /* each closed this long after it opened */
#define QUERIES_PER_CONN 2      /* slow queries one socket may have waiting */
#define PART 65536              /* a larger message goes out in parts of this much, */
#define PARTS_AHEAD 4           /* at most this many ahead of what the panel has read */
#define STR_(x) #x
#define NCP_HTTP_STR(x) STR_(x)
#define RATE_PER_S 50.0         /* commands per socket: a continuous jog's keep-alive */
#define RATE_BURST 100.0        /* is 10/s, a person's clicking far less */

struct outmsg {
    unsigned char *buf;         /* LWS_PRE bytes, then the message */
    size_t len, off;            /* off: bytes already written (parts) */
    uint64_t id;                /* names its parts */
    unsigned parts_sent, parts_got;  /* the latter as the panel says (got) */
};

struct conn {
    struct lws *wsi;
    struct conn *next;
    int authed;
    int evicted;                /* an unauthenticated socket being closed */
    int queries;                /* waiting for the worker */
    uint64_t parts;             /* messages queued: the id of a large one's parts */
    uint64_t serial;            /* names it to the worker */
    lws_sorted_usec_list_t sul; /* the unauthenticated socket's end */
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
    struct ncp_http_floor floor; /* first: the handlers' view (server_int.h) */
    struct ncp_http_opts o;
    char token[NCP_HTTP_TOKEN_LEN + 1];
    struct ncp_nck_serve_hook hook;
    struct lws_context *ctx;
    struct lws_http_mount mount, upload_mount;
    struct lws_protocols protocols[4];
    pthread_t thread;
    atomic_int stop;
    int32_t next_client;

    struct ncp_http_policy policy;
    struct ncp_http_jobs *jobs;
    pthread_mutex_t prog_mu;    /* guards prog: the serving thread swaps it */
    struct ncp_http_prog *prog;

    pthread_mutex_t mu;         /* guards what the threads share: */
    ncp_command_t cmds[CMD_QUEUE];
    unsigned cmd_head, cmd_n;
    ncp_command_t estops[ESTOP_QUEUE];
    unsigned estop_head, estop_n;
    uint64_t loads;             /* loads accepted */
    char loaded_path[256];
    ncp_status_t status;
    int64_t status_seq;         /* 0: none yet */
    ncp_ack_t acks[NOTE_QUEUE];
    unsigned ack_head, ack_n;
    ncp_event_t events[NOTE_QUEUE];
    unsigned ev_head, ev_n;
    struct ncp_http_stats stats;

    /* this thread's own */
    struct conn *conns;         /* newest first */
    int n_authed, n_unauth;
    uint64_t next_serial;
    uint64_t loads_told;
    unsigned char *status_msg;  /* LWS_PRE + the newest status as JSON */
    size_t status_len;
    int64_t status_msg_seq;
};

static void count(struct ncp_http *h, uint64_t *field)
{
    pthread_mutex_lock(&h->mu);
    (*field)++;
    pthread_mutex_unlock(&h->mu);
}

_Static_assert(offsetof(struct ncp_http, floor) == 0,
               "the handlers find the floor at the context's user (server_int.h)");

/* the floor's count: any thread */
static void count_stat(void *ctx, enum ncp_http_stat which)
{
    struct ncp_http *h = ctx;
    struct ncp_http_stats *st = &h->stats;
    uint64_t *field = which == NCP_HTTP_STAT_NO_TOKEN ? &st->no_token
                    : which == NCP_HTTP_STAT_READONLY ? &st->readonly
                    : which == NCP_HTTP_STAT_OVERSIZED ? &st->oversized
                    : which == NCP_HTTP_STAT_UPLOADS ? &st->uploads
                    : which == NCP_HTTP_STAT_FOREIGN_ORIGIN ? &st->foreign_origin
                    : which == NCP_HTTP_STAT_BAD_HOST ? &st->bad_host
                    : which == NCP_HTTP_STAT_BAD_REQUEST ? &st->bad_request
                    : which == NCP_HTTP_STAT_UNAUTH_CLOSED ? &st->unauth_closed
                                                           : &st->upload_bad;
    count(h, field);
}

/* ---- the serving thread's side (the hook) ------------------------------------------ */

static int hook_next_command(void *ctx, ncp_command_t *c)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->mu);
    int got = h->estop_n > 0 || h->cmd_n > 0;
    if (h->estop_n) {
        *c = h->estops[h->estop_head];
        h->estop_head = (h->estop_head + 1) % ESTOP_QUEUE;
        h->estop_n--;
    } else if (got) {
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

/* The worker's reference to the program's copy. */
static struct ncp_http_prog *prog_get(void *ctx)
{
    struct ncp_http *h = ctx;
    pthread_mutex_lock(&h->prog_mu);
    struct ncp_http_prog *p = h->prog;
    if (p)
        atomic_fetch_add(&p->refs, 1);
    pthread_mutex_unlock(&h->prog_mu);
    return p;
}

/* A load was accepted: a copy of the very text the NCK checked, taken on
 * the serving thread before its next command can load another. Reading
 * the file again instead would show whatever was written over it since. */
static void hook_loaded(void *ctx, int channel, const char *path, const char *text, size_t len)
{
    (void)channel;
    struct ncp_http *h = ctx;
    int too_large = len > NCP_HTTP_PROGRAM_MAX;
    struct ncp_http_prog *p = malloc(sizeof *p + (too_large ? 0 : len) + 1);
    if (p) {
        atomic_init(&p->refs, 1);
        snprintf(p->path, sizeof p->path, "%s", path);
        p->len = len;
        p->too_large = too_large;
        if (!too_large)
            memcpy(p->text, text, len);
        p->text[too_large ? 0 : len] = 0;
    }
    /* out of memory: no copy at all rather than the previous program's */
    pthread_mutex_lock(&h->prog_mu);
    struct ncp_http_prog *old = h->prog;
    h->prog = p;
    pthread_mutex_unlock(&h->prog_mu);
    if (old)
        ncp_http_prog_put(old);
    pthread_mutex_lock(&h->mu);
    h->loads++;
    snprintf(h->loaded_path, sizeof h->loaded_path, "%s", path);
    pthread_mutex_unlock(&h->mu);
    lws_cancel_service(h->ctx);
}

static void wake(void *ctx)
{
    struct ncp_http *h = ctx;
    lws_cancel_service(h->ctx);
}

/* ---- this thread: sockets ----------------------------------------------------------- */

static void pop(struct conn *c, unsigned i)
{
    free(c->out[(c->out_head + i) % OUT_QUEUE].buf);
    for (; i > 0; i--)
        c->out[(c->out_head + i) % OUT_QUEUE] = c->out[(c->out_head + i - 1) % OUT_QUEUE];
    c->out_head = (c->out_head + 1) % OUT_QUEUE;
    c->out_n--;
}

static void enqueue(struct ncp_http *h, struct conn *c, unsigned char *b, size_t len)
{
    if (c->out_n == OUT_QUEUE) {
        /* the oldest waiting message goes, unless it is partly sent: then
         * the one after it (the panel would wait for its last part) */
        pop(c, c->out[c->out_head].off ? 1 : 0);
        count(h, &h->stats.dropped);
    }
    c->out[(c->out_head + c->out_n++) % OUT_QUEUE] = (struct outmsg){ b, len, 0, ++c->parts, 0, 0 };
    lws_callback_on_writable(c->wsi);
}

/* Queues msg[len] (copied) for c; the oldest waiting message goes when full. */
static void send_copy(struct ncp_http *h, struct conn *c, const char *msg, size_t len)
{
    unsigned char *b = malloc(LWS_PRE + len);
    if (!b)
        return;
    memcpy(b + LWS_PRE, msg, len);
    enqueue(h, c, b, len);
}

static void refuse(struct ncp_http *h, struct conn *c, int32_t seq, const char *why)
{
    char msg[512];
    size_t n = (size_t)snprintf(msg, sizeof msg, "{\"type\": \"refused\", \"seq\": %d, \"reason\": ",
                                (int)seq);
    ncp_http_json_string(msg, sizeof msg - 2, &n, why, strlen(why));
    msg[n++] = '}';
    send_copy(h, c, msg, n);
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
                  "\"uploads\": %llu, \"upload_bad\": %llu, \"foreign_origin\": %llu, "
                  "\"bad_host\": %llu, \"bad_request\": %llu, \"unauth_closed\": %llu}}",
                  (unsigned long long)st.connections, (unsigned long long)st.commands,
                  (unsigned long long)st.bad_json, (unsigned long long)st.unknown,
                  (unsigned long long)st.oversized, (unsigned long long)st.flood,
                  (unsigned long long)st.no_token, (unsigned long long)st.readonly,
                  (unsigned long long)st.busy, (unsigned long long)st.dropped,
                  (unsigned long long)st.uploads, (unsigned long long)st.upload_bad,
                  (unsigned long long)st.foreign_origin, (unsigned long long)st.bad_host,
                  (unsigned long long)st.bad_request, (unsigned long long)st.unauth_closed);
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
        send_copy(h, c, msg, n);
    }
}

static void render_event(struct ncp_http *h, const ncp_event_t *e)
{
    char msg[2048];
    const char *kind = ncp_msg_event_kind_name(e->kind);
    kind = kind ? kind : "info";
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
        send_copy(h, c, msg, n);
}

/* The serving thread left something: acks, events, a newer status. */
static struct conn *conn_of(struct ncp_http *h, uint64_t serial)
{
    for (struct conn *c = h->conns; c; c = c->next)
        if (c->serial == serial)
            return c;
    return NULL;
}

/* The worker's finished answers to their sockets (if still there). */
static void take_answers(struct ncp_http *h)
{
    uint64_t serial;
    struct ncp_http_msg m;
    while (ncp_http_jobs_take(h->jobs, &serial, &m)) {
        struct conn *c = conn_of(h, serial);
        if (!c) {
            free(m.buf);
            continue;
        }
        c->queries--;
        if (m.buf)
            enqueue(h, c, m.buf, m.len);
    }
}

/* A load was accepted: the operators' panels ask for its text and preview
 * again (the path alone may not have changed: the file was loaded anew). */
static void tell_loads(struct ncp_http *h)
{
    pthread_mutex_lock(&h->mu);
    uint64_t loads = h->loads;
    char path[sizeof h->loaded_path];
    memcpy(path, h->loaded_path, sizeof path);
    pthread_mutex_unlock(&h->mu);
    if (loads == h->loads_told)
        return;
    h->loads_told = loads;
    char msg[600];
    size_t n = (size_t)snprintf(msg, sizeof msg, "{\"type\": \"loaded\", \"path\": ");
    ncp_http_json_string(msg, sizeof msg - 2, &n, path, strlen(path));
    msg[n++] = '}';
    for (struct conn *c = h->conns; c; c = c->next)
        if (c->authed)
            send_copy(h, c, msg, n);
}

/* The serving thread or the worker left something: acks, events, loads,
 * answers, a newer status. */
static void take_notes(struct ncp_http *h)
{
    tell_loads(h);
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
    take_answers(h);
    render_status(h);
    for (struct conn *c = h->conns; c; c = c->next)
        if (c->status_sent != h->status_msg_seq && h->status_len)
            lws_callback_on_writable(c->wsi);
}

static int write_status(struct ncp_http *h, struct conn *c)
{
    if (c->status_sent && h->status_msg_seq > c->status_sent + 1)
        count(h, &h->stats.status_skipped);
    c->status_sent = h->status_msg_seq;
    if (lws_write(c->wsi, h->status_msg + LWS_PRE, h->status_len, LWS_WRITE_TEXT) <
        (int)h->status_len)
        return -1;
    count(h, &h->stats.status_sent);
    return 0;
}

/* The next part of a large message: {"type": "part", "id", "last", "data"}
 * with up to PART bytes of its text, cut between UTF-8 characters; the
 * panel joins the parts and reads the whole. */
static int write_part(struct conn *c, struct outmsg *m)
{
    const unsigned char *text = m->buf + LWS_PRE;
    size_t n = m->len - m->off < PART ? m->len - m->off : PART;
    while (m->off + n < m->len && n > 1 && (text[m->off + n] & 0xc0) == 0x80)
        n--;
    int last = m->off + n == m->len;
    m->parts_sent++;
    size_t size = LWS_PRE + 64 + 6 * n + 8;
    unsigned char *b = malloc(size);
    if (!b)
        return -1;
    char *p = (char *)b + LWS_PRE;
    size_t k = (size_t)snprintf(p, 64, "{\"type\": \"part\", \"id\": %llu, \"last\": %s, \"data\": ",
                                (unsigned long long)m->id, last ? "true" : "false");
    ncp_http_json_string(p, size - LWS_PRE - 2, &k, (const char *)text + m->off, n);
    p[k++] = '}';
    int rc = lws_write(c->wsi, b + LWS_PRE, k, LWS_WRITE_TEXT);
    free(b);
    m->off += n;
    if (last)
        pop(c, 0);
    return rc < (int)k ? -1 : 0;
}

/* A large message's next part may go: not more than PARTS_AHEAD of them
 * ahead of the panel's reading. The socket's own buffers (megabytes on a
 * fast link) would otherwise fill with parts, and an ack written after them
 * reaches the panel only once it has read and parsed all of those. */
static int part_may_go(const struct outmsg *m)
{
    return m->parts_sent - m->parts_got < PARTS_AHEAD;
}

/* The first message small enough to go whole that waits behind a large
 * one at the head (its place in the queue), or 0: none, or the head is small. */
static unsigned small_behind(const struct conn *c)
{
    if (!c->out_n || c->out[c->out_head].len <= PART)
        return 0;
    for (unsigned i = 1; i < c->out_n; i++)
        if (c->out[(c->out_head + i) % OUT_QUEUE].len <= PART)
            return i;
    return 0;
}

/* Something this socket could be sent now: asking for a writable callback
 * otherwise would only spin. */
static int has_writable(const struct ncp_http *h, const struct conn *c)
{
    if (h->status_len && c->status_sent != h->status_msg_seq)
        return 1;
    if (!c->out_n)
        return 0;
    const struct outmsg *m = &c->out[c->out_head];
    return m->len <= PART || part_may_go(m) || small_behind(c);
}

/* One message per call. A large one goes in parts, each a message of its
 * own, so that what is queued behind it (an E-stop's ack above all) and the
 * status go out between them: WebSocket cannot interleave the fragments of
 * one message with another, and a preview of megabytes would otherwise hold
 * the ack for as long as it takes to send. */
static int write_next(struct ncp_http *h, struct conn *c)
{
    int status_due = h->status_len && c->status_sent != h->status_msg_seq;
    int rc = 0;
    if (c->out_n) {
        struct outmsg *m = &c->out[c->out_head];
        unsigned small = small_behind(c);
        if (small) {
            m = &c->out[(c->out_head + small) % OUT_QUEUE];
            rc = lws_write(c->wsi, m->buf + LWS_PRE, m->len, LWS_WRITE_TEXT) < (int)m->len;
            pop(c, small);
        } else if (m->len > PART && ((m->off && status_due) || !part_may_go(m))) {
            if (status_due)
                rc = write_status(h, c);
        } else if (m->len > PART) {
            rc = write_part(c, m);
        } else {
            rc = lws_write(c->wsi, m->buf + LWS_PRE, m->len, LWS_WRITE_TEXT) < (int)m->len;
            pop(c, 0);
        }
    } else if (status_due) {
        rc = write_status(h, c);
    }
    if (rc)
        return -1;
    if (has_writable(h, c))
        lws_callback_on_writable(c->wsi);
    return 0;
}

/* The panel has read n parts of message id: a part held back may go. 1 when
 * that was news, 0 when no such message or parts were sent (then the
 * message is refused like any other bad one). */
static int take_got(struct conn *c, uint64_t id, unsigned n)
{
    if (!c->out_n)
        return 0;
    struct outmsg *m = &c->out[c->out_head];
    if (m->id != id || n <= m->parts_got || n > m->parts_sent)
        return 0;
    m->parts_got = n;
    lws_callback_on_writable(c->wsi);
    return 1;
}

/* Whether message id was sent whole to c (its id given, no longer queued). */
static int got_of_sent(const struct conn *c, uint64_t id)
{
    if (id == 0 || id > c->parts)
        return 0;
    for (unsigned i = 0; i < c->out_n; i++)
        if (c->out[(c->out_head + i) % OUT_QUEUE].id == id)
            return 0;
    return 1;
}

/* A socket's command into the serving thread's queue; an E-stop into its
 * own, which the serving thread empties first and which never refuses one. */
static void submit(struct ncp_http *h, struct conn *c, const ncp_command_t *cmd)
{
    if (!c->authed) {
        count(h, &h->stats.no_token);
        refuse(h, c, cmd->seq, "no valid token: this panel may only watch");
        return;
    }
    if (h->o.readonly) {
        count(h, &h->stats.readonly);
        refuse(h, c, cmd->seq, "the panel is read-only (--http-readonly)");
        return;
    }
    pthread_mutex_lock(&h->mu);
    int full = 0;
    if (cmd->kind == NCP_CMD_ESTOP) {
        /* full of E-stops already: the oldest of them is as good as this one */
        if (h->estop_n == ESTOP_QUEUE) {
            h->estop_head = (h->estop_head + 1) % ESTOP_QUEUE;
            h->estop_n--;
        }
        h->estops[(h->estop_head + h->estop_n++) % ESTOP_QUEUE] = *cmd;
        h->stats.commands++;
    } else if (h->cmd_n == CMD_QUEUE) {
        full = 1;
        h->stats.busy++;
    } else {
        h->cmds[(h->cmd_head + h->cmd_n++) % CMD_QUEUE] = *cmd;
        h->stats.commands++;
    }
    pthread_mutex_unlock(&h->mu);
    if (full)
        refuse(h, c, cmd->seq, "the NCK is busy: command not taken");
}

/* Token bucket per socket: 0 when this message may be taken. */
static int over_rate(struct conn *c)
{
    int64_t now = ncp_mono_ns();
    c->bucket += (double)(now - c->bucket_ns) * 1e-9 * RATE_PER_S;
    if (c->bucket > RATE_BURST)
        c->bucket = RATE_BURST;
    c->bucket_ns = now;
    if (c->bucket < 1.0)
        return 1;
    c->bucket -= 1.0;
    return 0;
}

/* A slow query to the worker, a few per socket at most. */
static void query(struct ncp_http *h, struct conn *c, enum ncp_http_req r)
{
    if (!c->authed) {
        count(h, &h->stats.no_token);
        refuse(h, c, 0, "no valid token: this panel may only watch");
        return;
    }
    if (c->queries >= QUERIES_PER_CONN || ncp_http_jobs_submit(h->jobs, c->serial, r)) {
        count(h, &h->stats.busy);
        refuse(h, c, 0, "the panel is still answering earlier queries: ask again later");
        return;
    }
    c->queries++;
}

/* A load of a plain name is of the program folder's file (the list shows
 * names, uploads land there): made absolute for the NCK, whose own relative
 * paths start in serve's working directory. 0, or -1 when it does not fit. */
static int program_path(const struct ncp_http *h, ncp_command_t *cmd)
{
    char path[sizeof cmd->text];
    if (ncp_http_program_path(h->o.program_dir, (const char *)cmd->text, path, sizeof path))
        return -1;
    memcpy(cmd->text, path, sizeof path);
    return 0;
}

static void on_message(struct ncp_http *h, struct conn *c)
{
    if (c->rx_over) {
        count(h, &h->stats.oversized);
        refuse(h, c, 0, "message too large");
        return;
    }
    ncp_command_t cmd;
    int unknown;
    char why[128];
    enum ncp_http_req r = NCP_HTTP_REQ_BAD;
    /* what the panel has read of a large answer: before the rate, since
     * parts are not held back by it either, and only a got that names parts
     * sent and not yet read is taken here (a few per part at most) */
    int parsed = memmem(c->rx, c->rx_len, "\"got\"", 5) != NULL;
    if (parsed) {
        r = ncp_http_parse_request(c->rx, c->rx_len, c->client_id, &cmd, &unknown, why,
                                   sizeof why);
        if (r == NCP_HTTP_REQ_GOT && take_got(c, (uint64_t)cmd.ivalue[0], (unsigned)cmd.ivalue[1]))
            return;
    }
    /* no answer to a flood: answering would be one more. An E-stop is
     * never held back by its socket's rate: only one that names it is
     * parsed past the limit. */
    if (over_rate(c) && !memmem(c->rx, c->rx_len, "estop", 5)) {
        count(h, &h->stats.flood);
        return;
    }
    if (!parsed)
        r = ncp_http_parse_request(c->rx, c->rx_len, c->client_id, &cmd, &unknown, why,
                                   sizeof why);
    switch (r) {
    case NCP_HTTP_REQ_COMMAND:
        if (cmd.kind == NCP_CMD_LOAD && program_path(h, &cmd)) {
            refuse(h, c, cmd.seq, "the program's path is too long");
            break;
        }
        submit(h, c, &cmd);
        break;
    case NCP_HTTP_REQ_BAD:
        count(h, unknown ? &h->stats.unknown : &h->stats.bad_json);
        refuse(h, c, 0, why);
        break;
    case NCP_HTTP_REQ_GOT:
        /* the last parts' gots cross the message's end on the wire: a
         * message sent whole is no news, and no error either */
        if (!got_of_sent(c, (uint64_t)cmd.ivalue[0])) {
            count(h, &h->stats.bad_json);
            refuse(h, c, 0, "got: no such parts sent");
        }
        break;
    default:
        query(h, c, r);
        break;
    }
}

/* the floor's token check */
static int token_ok(void *ctx, struct lws *wsi)
{
    const struct ncp_http *h = ctx;
    char buf[128];
    const char *t = lws_get_urlarg_by_name(wsi, "token=", buf, (int)sizeof buf);
    if (!t || strlen(t) != NCP_HTTP_TOKEN_LEN)
        return 0;
    unsigned diff = 0;   /* the same time for every wrong token */
    for (int i = 0; i < NCP_HTTP_TOKEN_LEN; i++)
        diff |= (unsigned)(t[i] ^ h->token[i]);
    return diff == 0;
}

/* An unauthenticated socket's time is up, or a newer one needs its place. */
static void close_unauth(struct ncp_http *h, struct conn *c)
{
    if (c->evicted)
        return;
    c->evicted = 1;
    h->n_unauth--;
    lws_sul_cancel(&c->sul);
    count(h, &h->stats.unauth_closed);
    lws_close_reason(c->wsi, LWS_CLOSE_STATUS_POLICY_VIOLATION,
                     (unsigned char *)"no valid token", 14);
    lws_set_timeout(c->wsi, PENDING_TIMEOUT_USER_OK, LWS_TO_KILL_ASYNC);
}

static void unauth_expired(lws_sorted_usec_list_t *sul)
{
    struct conn *c = (struct conn *)(void *)((char *)sul - offsetof(struct conn, sul));
    close_unauth(lws_context_user(lws_get_context(c->wsi)), c);
}

/* A new socket without the token: into the small pool, the oldest out if
 * it is full, and a time limit on it. */
static void admit_unauth(struct ncp_http *h, struct conn *c)
{
    while (h->n_unauth >= UNAUTH_MAX) {
        struct conn *oldest = NULL;
        for (struct conn *o = h->conns; o; o = o->next)
            if (!o->authed && !o->evicted && o != c)
                oldest = o;
        if (!oldest)
            break;
        close_unauth(h, oldest);
    }
    h->n_unauth++;
    lws_sul_schedule(lws_get_context(c->wsi), 0, &c->sul, unauth_expired,
                     (lws_usec_t)UNAUTH_MS * 1000);
}

static void drop_conn(struct ncp_http *h, struct conn *c)
{
    for (struct conn **p = &h->conns; *p; p = &(*p)->next)
        if (*p == c) {
            *p = c->next;
            if (c->authed)
                h->n_authed--;
            else if (!c->evicted)
                h->n_unauth--;
            break;
        }
    lws_sul_cancel(&c->sul);
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
        /* only operators count against MAX_CONNS; others take the pool */
        return token_ok(h, wsi) && h->n_authed >= MAX_CONNS;
    case LWS_CALLBACK_ESTABLISHED:
        /* the session's memory is new here; the URL's query still readable */
        memset(c, 0, sizeof *c);
        c->authed = token_ok(h, wsi);
        c->wsi = wsi;
        c->serial = ++h->next_serial;
        c->client_id = NCP_HTTP_CLIENT_TAG | (h->next_client++ & ~NCP_HTTP_CLIENT_MASK);
        c->bucket = RATE_BURST;
        c->bucket_ns = ncp_mono_ns();
        c->next = h->conns;
        h->conns = c;
        if (c->authed)
            h->n_authed++;
        else
            admit_unauth(h, c);
        count(h, &h->stats.connections);
        {
            char hello[2048];
            int n = snprintf(hello, sizeof hello,
                             "{\"type\": \"hello\", \"authed\": %s, \"readonly\": %s%s%s}",
                             c->authed ? "true" : "false", h->o.readonly ? "true" : "false",
                             c->authed ? "" : ", \"closes_in_ms\": " NCP_HTTP_STR(UNAUTH_MS),
                             h->o.hello_extra ? h->o.hello_extra : "");
            if (n > 0 && (size_t)n < sizeof hello)
                send_copy(h, c, hello, (size_t)n);
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
    char why[240];
    if (ncp_http_policy_init(&h->policy, o->addr, o->port, o->allow_origin, o->allow_host, why,
                             sizeof why)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: [HTTP] %s", why);
        goto fail;
    }
    if (o->program_dir && o->program_dir[0]) {
        struct stat pd;
        int err = stat(o->program_dir, &pd) != 0 ? errno : 0;
        if (err || !S_ISDIR(pd.st_mode)) {
            ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                         "--http: the program folder %s ([DISPLAY] PROGRAM_PREFIX): %s",
                         o->program_dir, err ? strerror(err) : "not a folder");
            goto fail;
        }
    }
    if (make_token(h->token)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: no random numbers for the token");
        goto fail;
    }
    h->next_client = (int32_t)(h->token[0] * 4099 + h->token[1]);
    h->floor = (struct ncp_http_floor){ .opts = &h->o, .policy = &h->policy,
                                        .count = count_stat, .token_ok = token_ok, .ctx = h };
    pthread_mutex_init(&h->mu, NULL);
    pthread_mutex_init(&h->prog_mu, NULL);
    h->hook = (struct ncp_nck_serve_hook){ .next_command = hook_next_command, .ack = hook_ack,
                                           .status = hook_status, .event = hook_event,
                                           .loaded = hook_loaded, .ctx = h };
    h->mount = (struct lws_http_mount){ .mountpoint = "/", .origin = h->o.web_root,
                                        .def = "index.html",
                                        .origin_protocol = LWSMPRO_FILE, .mountpoint_len = 1 };
    /* the gate is the default protocol: every request and upgrade meets it first */
    h->protocols[0] = (struct lws_protocols){ "http", ncp_http_on_gate, 0, 0, 0, NULL, 0 };
    h->protocols[1] = (struct lws_protocols){ "ncp-panel", on_ws, sizeof(struct conn),
                                              NCP_HTTP_MSG_MAX, 0, NULL, 0 };
    h->protocols[2] = (struct lws_protocols){ "ncp-upload", ncp_http_on_upload,
                                              ncp_http_upload_session_size(), 0, 0, NULL, 0 };
    h->upload_mount = (struct lws_http_mount){ .mountpoint = "/upload", .origin = "ncp-upload",
                                               .origin_protocol = LWSMPRO_CALLBACK,
                                               .mountpoint_len = 7 };
    h->mount.mount_next = &h->upload_mount;
    /* what a serve killed mid-upload left behind: every temporary, as one
     * folder has one serve (a second one's upload in flight would fail and
     * say so, never store a part) */
    ncp_http_sweep_uploads(h->o.program_dir, 0);
    struct ncp_http_jobs_env env = { .paths = { h->o.self_exe, h->o.program_dir,
                                                h->o.tool_table, h->o.history_file },
                                     .prog_get = prog_get,
                                     .wake = wake, .ctx = h };
    lws_set_log_level(LLL_ERR, NULL);
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = o->port;
    info.iface = h->o.addr;
    info.protocols = h->protocols;
    info.mounts = &h->mount;
    info.user = h;
    info.options = LWS_SERVER_OPTION_VALIDATE_UTF8;
    /* a connection that holds a half-sent request holds it this long */
    info.timeout_secs_ah_idle = 2;
    if (!strchr(h->o.addr, ':'))
        info.options |= LWS_SERVER_OPTION_DISABLE_IPV6;
    h->ctx = lws_create_context(&info);
    if (!h->ctx) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: cannot listen on %s port %d (in use?)",
                     o->addr, o->port);
        goto fail_locks;
    }
    if (!(h->jobs = ncp_http_jobs_start(&env))) {
        lws_context_destroy(h->ctx);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: cannot start its worker thread");
        goto fail_locks;
    }
    int rc = ncp_http_spawn(&h->thread, serve_loop, h);
    if (rc) {
        ncp_http_jobs_stop(h->jobs);
        lws_context_destroy(h->ctx);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: cannot start its thread");
        goto fail_locks;
    }
    return h;
fail_locks:
    pthread_mutex_destroy(&h->prog_mu);
    pthread_mutex_destroy(&h->mu);
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
    ncp_http_jobs_stop(h->jobs);   /* a running preview is killed */
    lws_context_destroy(h->ctx);   /* closes the sockets: CLOSED frees their queues */
    if (h->prog)
        ncp_http_prog_put(h->prog);
    pthread_mutex_destroy(&h->prog_mu);
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
