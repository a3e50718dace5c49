/* The NCK on LCM: commands in on <prefix>CMD, an ACK for each, STATUS at the
 * status rate and at every state change, EVENTs as they come. One thread (the
 * caller's) does all of it; the NCK's real-time threads never see a message.
 * Several NC channels share the transport: each message carries its
 * channel, a command goes to the NCK of its channel only. */
#include "control.h"

#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/clock.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <time.h>

/* Each client's last command, kept for as long as one of its commands can
 * still be fresh (its latest deadline): a repeated seq is a resend (answered
 * with the same ACK, not acted on twice), an older one a replay (dropped).
 * A command past its deadline is refused anyway, so after it the entry is
 * of no use and is dropped: the table holds the clients of the last
 * FRESH_MAX_US at most, and only clients that hold the key can add one. */
#define FRESH_MAX_US (600LL * 1000000)  /* the longest a command may stay fresh */
#define CLOCK_AHEAD_MAX_US (5LL * 1000000) /* a client's clock ahead of ours, at most */
struct client {
    int32_t id, seq;
    int64_t keep_until_us;           /* CLOCK_REALTIME: its latest deadline */
    ncp_ack_t ack;
    int pending;                     /* seq's answer is not known yet: a resend waits */
};

struct serve_channel {
    struct ncp_nck *nck;
    int num;                         /* the messages' channel field */
    int32_t jog_client;              /* whose keep-alives hold a continuous jog */
    int pending;                     /* a command answered later (a load's check, or one
                                        that waits for the NCK's disk writer) */
    int32_t pending_client, pending_seq;
    int pending_kind;                /* its enum ncp_nck_cmd_kind */
    int faulted;                     /* in fault when last polled */
};

struct serve {
    struct serve_channel ch[NCP_NCK_CHANNELS_MAX];
    int n_ch;
    struct ncp_msg *msg;
    struct client *clients;
    size_t n_clients, cap_clients;
    uint64_t replayed, duplicates, stale;
    int64_t status_seq, event_seq;
    int fault_seen;
    const struct ncp_nck_serve_hook *hook;   /* another front end, or NULL */
};

static int64_t utime_now(void)
{
    struct timeval tv;
    gettimeofday(&tv, NULL);
    return (int64_t)tv.tv_sec * 1000000 + tv.tv_usec;
}

/* The client's entry, made when new (NULL: out of memory). Entries whose
 * every command is past its deadline make room first. */
static struct client *client_of(struct serve *sv, int32_t id, int64_t now_us)
{
    for (size_t i = 0; i < sv->n_clients; i++)
        if (sv->clients[i].id == id)
            return &sv->clients[i];
    size_t kept = 0;
    for (size_t i = 0; i < sv->n_clients; i++)
        if (sv->clients[i].pending || sv->clients[i].keep_until_us >= now_us)
            sv->clients[kept++] = sv->clients[i];
    sv->n_clients = kept;
    if (sv->n_clients == sv->cap_clients) {
        size_t cap = sv->cap_clients ? 2 * sv->cap_clients : 16;
        struct client *grown = realloc(sv->clients, cap * sizeof *grown);
        if (grown == NULL)
            return NULL;
        sv->clients = grown;
        sv->cap_clients = cap;
    }
    struct client *c = &sv->clients[sv->n_clients++];
    memset(c, 0, sizeof *c);
    c->id = id;
    return c;
}

static struct serve_channel *channel_of(struct serve *sv, int num)
{
    for (int k = 0; k < sv->n_ch; k++)
        if (sv->ch[k].num == num)
            return &sv->ch[k];
    return NULL;
}

static void send_status(struct serve *sv, const struct serve_channel *ch)
{
    struct ncp_nck_snapshot st;
    ncp_nck_get_status(ch->nck, &st);
    struct ncp_msg_stats ms;
    ncp_msg_get_stats(sv->msg, &ms);
    ncp_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = utime_now();
    m.seq = ++sv->status_seq;
    m.channel = (int8_t)ch->num;
    m.state = (int8_t)st.state;
    snprintf((char *)m.program, sizeof m.program, "%s", st.program);
    m.line = (int32_t)st.line;
    m.n_axes = (int8_t)st.n_axes;
    for (int j = 0; j < st.n_axes && j < 9; j++) {
        m.axes[j] = (uint8_t)st.axes[j];
        m.homed[j] = (int8_t)st.homed[j];
        m.pos_cmd[j] = st.pos_cmd[j];
        m.pos_act[j] = st.pos_act[j];
        m.g5x_offset[j] = st.g5x_offset[j];
    }
    m.vel = st.vel;
    m.feed_override = st.feed_override;
    m.rapid_override = st.rapid_override;
    m.spindle_override = st.spindle_override;
    m.spindle_speed = st.spindle_speed;
    m.spindle_dir = (int8_t)st.spindle_dir;
    m.mist = (int8_t)st.mist;
    m.flood = (int8_t)st.flood;
    m.tool = st.tool;
    m.g5x_index = (int8_t)st.g5x_index;
    _Static_assert(sizeof m.gcodes / sizeof m.gcodes[0] == NCP_AG__N &&
                   sizeof m.mcodes / sizeof m.mcodes[0] == NCP_AM__N, "status holds every group");
    memcpy(m.gcodes, st.active.g, sizeof m.gcodes);
    memcpy(m.mcodes, st.active.m, sizeof m.mcodes);
    m.g64_p = st.active.g64_p;
    m.g64_q = st.active.g64_q;
    m.step_mode = (int8_t)st.step_mode;
    snprintf((char *)m.error, sizeof m.error, "%s", st.error);
    m.commands = (int64_t)ms.commands;
    m.garbage = (int64_t)ms.garbage;
    m.auth_failed = (int64_t)ms.auth_failed;
    m.stale = (int64_t)sv->stale;
    m.replayed = (int64_t)sv->replayed;
    m.rejected = (int64_t)st.rejected;
    m.cycles = (int64_t)st.cycles;
    m.deadline_misses = (int64_t)st.deadline_misses;
    m.latency_max_us = st.latency_max_us;
    m.estimate_state = (int8_t)st.estimate_state;
    m.estimate_s = st.estimate_s;
    m.estimate_path_mm = st.estimate_path_mm;
    m.estimate_ferr_mm = st.estimate_ferr_mm;
    m.estimate_compute_s = st.estimate_compute_s;
    m.estimate_pauses = st.estimate_pauses;
    for (int j = 0; j < 9 && j < NCP_AXES; j++) {
        m.estimate_min[j] = (float)st.estimate_min[j];
        m.estimate_max[j] = (float)st.estimate_max[j];
    }
    m.remaining_s = st.remaining_s;
    m.program_time_s = st.program_time_s;
    m.n_drives = (int8_t)(st.n_drives < 9 ? st.n_drives : 9);
    for (int k = 0; k < m.n_drives; k++) {
        m.drive_axis[k] = (uint8_t)st.drive_axis[k];
        m.drive_node[k] = (int8_t)st.drive_node[k];
        m.drive_statusword[k] = (int16_t)st.drive_statusword[k];
        m.drive_error[k] = (int16_t)st.drive_error[k];
    }
    m.n_llcs = (int8_t)(st.n_llcs < 9 ? st.n_llcs : 9);
    m.llc_dp = (int8_t)st.llc_dp;
    for (int k = 0; k < m.n_llcs; k++) {
        m.llc_axis[k] = (uint8_t)st.llc_axis[k];
        m.llc_state[k] = (int8_t)st.llc_state[k];
        /* within +-35 min: an offset beyond that is no clock anyone runs */
        int64_t us = st.llc_clock_offset_ns[k] / 1000;
        m.llc_clock_offset_us[k] = (int32_t)(us > INT32_MAX ? INT32_MAX : us < -INT32_MAX ? -INT32_MAX : us);
        m.llc_ferr_nm[k] = st.llc_ferr_nm[k];
        m.llc_error[k] = (int8_t)st.llc_error[k];
    }
    ncp_msg_send_status(sv->msg, &m);
    if (sv->hook && sv->hook->status)
        sv->hook->status(sv->hook->ctx, &m);
    if (st.state == NCP_ST_FAULT)
        sv->fault_seen = 1;
}

static void send_events(struct serve *sv, const struct serve_channel *ch)
{
    struct ncp_nck_event ev;
    while (ncp_nck_next_event(ch->nck, &ev)) {
        ncp_event_t m;
        memset(&m, 0, sizeof m);
        m.utime = utime_now();
        m.seq = ++sv->event_seq;
        m.channel = (int8_t)ch->num;
        m.kind = (int8_t)ev.kind;
        snprintf((char *)m.file, sizeof m.file, "%s", ev.file);
        m.line = (int32_t)ev.line;
        m.col = (int32_t)ev.col;
        snprintf((char *)m.text, sizeof m.text, "%s", ev.text);
        ncp_msg_send_event(sv->msg, &m);
        if (sv->hook && sv->hook->event)
            sv->hook->event(sv->hook->ctx, &m);
        char who[16] = "";
        if (sv->n_ch > 1)
            snprintf(who, sizeof who, "ch%d: ", ch->num);
        if (ev.kind >= NCP_EV_ERROR)
            fprintf(stderr, "cnc-run serve: %s%s%s%s%s\n", who, ev.file[0] ? ev.file : "",
                    ev.file[0] ? ": " : "", ev.kind == NCP_EV_FAULT ? "fault: " : "error: ",
                    ev.text);
    }
}

static void send_ack(struct serve *sv, const ncp_ack_t *a)
{
    ncp_msg_send_ack(sv->msg, a);
    if (sv->hook && sv->hook->ack)
        sv->hook->ack(sv->hook->ctx, a);
}

/* A refusal that needs no NCK (state -1: none asked), sent and kept as the
 * client's last ACK. */
static void refuse(struct serve *sv, const ncp_command_t *c, ncp_ack_t *a, const char *why)
{
    memset(a, 0, sizeof *a);
    a->utime = utime_now();
    a->client_id = c->client_id;
    a->seq = c->seq;
    a->channel = c->channel;
    a->result = NCP_ACK_T_REJECTED;
    a->state = -1;
    snprintf((char *)a->reason, sizeof a->reason, "%s", why);
    send_ack(sv, a);
}

/* A command for a channel this service does not have: refused, so that a
 * client with a wrong --channel hears why instead of waiting. */
static void refuse_channel(struct serve *sv, const ncp_command_t *c, ncp_ack_t *a)
{
    char list[64] = "";
    for (int k = 0, at = 0; k < sv->n_ch && at < (int)sizeof list; k++) {
        int w = snprintf(list + at, sizeof list - (size_t)at, "%s%d", k ? ", " : "", sv->ch[k].num);
        at += w > 0 ? w : 0;
    }
    char why[sizeof a->reason];
    snprintf(why, sizeof why, "no NC channel %d here (channels: %s)", c->channel, list);
    refuse(sv, c, a, why);
}

static void answer(struct serve *sv, struct serve_channel *ch, ncp_ack_t *a, int32_t client,
                   int32_t seq, int rc, const char *why, int said);
static void answer_pending(struct serve *sv, struct serve_channel *ch);

/* Why a command cannot act now (NULL: it may): its deadline passed, or it
 * claims more than a command may. local: the panel's, handed over in this
 * process (no clock of another host, no network in between). */
static const char *unfresh(const ncp_command_t *c, int64_t now_us, char *why, size_t len)
{
    if (c->deadline_utime <= c->utime || c->deadline_utime - c->utime > FRESH_MAX_US)
        return snprintf(why, len, "the command's deadline is not within %lld s of its "
                                  "sending: refused",
                        FRESH_MAX_US / 1000000), why;
    if (c->utime > now_us + CLOCK_AHEAD_MAX_US)
        return snprintf(why, len, "the command was sent %.1f s in this NCK's future: are the "
                                  "two hosts' clocks in step (NTP, PTP)?",
                        (double)(c->utime - now_us) * 1e-6), why;
    if (now_us > c->deadline_utime)
        return snprintf(why, len, "the command came %.0f ms after its deadline (its client "
                                  "had given up): not acted on",
                        (double)(now_us - c->deadline_utime) * 1e-3), why;
    return NULL;
}

static void act(struct serve *sv, struct serve_channel *ch, struct client *cl,
                const ncp_command_t *c);

/* The channels of one service share one E-stop chain, as a machine's
 * channels do in LinuxCNC and Sinumerik: an E-stop of any channel freezes
 * every channel's setpoints at once (the others before its ACK goes out),
 * whatever backend each runs on. Each channel comes back with its own reset. */
static void estop_others(struct serve *sv, const struct serve_channel *from)
{
    for (int k = 0; k < sv->n_ch; k++) {
        struct serve_channel *o = &sv->ch[k];
        if (o == from)
            continue;
        struct ncp_nck_cmd e;
        memset(&e, 0, sizeof e);
        e.kind = NCP_CMD_ESTOP;
        char why[8];
        int was = o->nck->state;
        ncp_nck_command(o->nck, &e, why, sizeof why);
        if (was != NCP_ST_ESTOP)
            nck_post(&o->nck->core, NCP_EV_INFO, NULL, 0, 0,
                     "E-stop of channel %d: one E-stop stops every channel", from->num);
    }
}

/* An E-stop is never conditional: whatever its sequence number, however
 * often it comes and however late, an authenticated one acts (stopping is
 * never the wrong answer to it), and it is answered. */
static void on_estop(struct serve *sv, struct serve_channel *ch, struct client *cl,
                     const ncp_command_t *c)
{
    if (c->seq > cl->seq)
        cl->seq = c->seq;
    if (!ch) {
        refuse_channel(sv, c, &cl->ack);
        return;
    }
    estop_others(sv, ch);
    act(sv, ch, cl, c);
}

/* A channel gone into fault (its drives, its LLCs, its following error):
 * the others stop along their paths rather than run on beside a machine
 * that stopped under them; they are not faulted, and run again when told. */
static void fault_stops_others(struct serve *sv)
{
    for (int k = 0; k < sv->n_ch; k++) {
        struct serve_channel *f = &sv->ch[k];
        /* from the fault on, not once its own drop ended in it */
        int faulted = f->nck->state == NCP_ST_FAULT ||
                      (f->nck->drop != NCK_DROP_NONE && f->nck->drop_after == NCP_ST_FAULT);
        int now = faulted && !f->faulted;
        f->faulted = faulted;
        for (int i = 0; now && i < sv->n_ch; i++) {
            struct serve_channel *o = &sv->ch[i];
            int st = o->nck->state;
            if (o == f || !(st == NCP_ST_RUNNING || st == NCP_ST_PAUSED ||
                            st == NCP_ST_STEPPING || st == NCP_ST_MDI ||
                            st == NCP_ST_JOGGING || st == NCP_ST_HOMING))
                continue;
            struct ncp_nck_cmd c;
            memset(&c, 0, sizeof c);
            c.kind = NCP_CMD_STOP;
            char why[64];
            if (ncp_nck_command(o->nck, &c, why, sizeof why) == 0)
                nck_post(&o->nck->core, NCP_EV_ERROR, NULL, 0, 0,
                         "stopped: channel %d is in fault (%.200s)", f->num, f->nck->error);
        }
    }
}

static void take_command(struct serve *sv, const ncp_command_t *c, int local)
{
    struct serve_channel *ch = channel_of(sv, c->channel);
    int64_t now_us = utime_now();
    struct client *cl = client_of(sv, c->client_id, now_us);
    if (cl == NULL)
        return;   /* out of memory: as if lost; the client resends */
    /* kept while its latest command could be fresh; a deadline further
     * out is refused below and keeps it no longer than any other */
    int64_t longest = now_us + FRESH_MAX_US + CLOCK_AHEAD_MAX_US;
    int64_t until = local || c->deadline_utime > longest ? longest : c->deadline_utime;
    if (until > cl->keep_until_us)
        cl->keep_until_us = until;
    if (c->kind == NCP_CMD_ESTOP) {
        on_estop(sv, ch, cl, c);
        return;
    }
    /* the panel's keep-alives carry no sequence number: it hands them over
     * in this process, where nothing can replay them */
    int numbered = !(local && c->kind == NCP_CMD_KEEPALIVE);
    if (numbered && cl->seq && c->seq == cl->seq) {
        sv->duplicates++;
        if (!cl->pending && c->kind != NCP_CMD_KEEPALIVE)
            send_ack(sv, &cl->ack);
        return;
    }
    if (numbered && cl->seq && c->seq < cl->seq) {
        sv->replayed++;
        return;
    }
    char why[sizeof cl->ack.reason];
    if (!local && unfresh(c, now_us, why, sizeof why)) {
        sv->stale++;
        cl->seq = c->seq;
        if (c->kind != NCP_CMD_KEEPALIVE)
            refuse(sv, c, &cl->ack, why);
        return;
    }
    if (c->kind == NCP_CMD_KEEPALIVE) {
        if (numbered)
            cl->seq = c->seq;
        /* only the jogging client's keep-alives hold its jog */
        if (ch && c->client_id == ch->jog_client) {
            struct ncp_nck_cmd k;
            memset(&k, 0, sizeof k);
            k.kind = NCP_CMD_KEEPALIVE;
            char kwhy[8];
            ncp_nck_command(ch->nck, &k, kwhy, sizeof kwhy);
        }
        return;
    }
    if (!ch) {
        cl->seq = c->seq;
        refuse_channel(sv, c, &cl->ack);
        return;
    }
    act(sv, ch, cl, c);
}

static void on_command(void *ctx, const ncp_command_t *c)
{
    take_command(ctx, c, 0);
}

/* The command, acted on: its ACK now, or when its NCK has the answer. */
static void act(struct serve *sv, struct serve_channel *ch, struct client *cl,
                const ncp_command_t *c)
{
    struct ncp_nck_cmd k;
    memset(&k, 0, sizeof k);
    k.kind = c->kind;
    _Static_assert(sizeof k.text == sizeof c->text, "command text as on the wire");
    memcpy(k.text, c->text, sizeof k.text);
    k.text[sizeof k.text - 1] = 0;
    for (int i = 0; i < 4; i++) {
        k.value[i] = c->value[i];
        k.ivalue[i] = c->ivalue[i];
    }
    ncp_ack_t *a = &cl->ack;
    memset(a, 0, sizeof *a);
    char why[sizeof a->reason];
    int rc = ncp_nck_command(ch->nck, &k, why, sizeof why);
    if (c->seq > cl->seq)   /* an E-stop's may be older: it never winds the table back */
        cl->seq = c->seq;
    if (rc == NCP_NCK_CMD_PENDING) {
        if (ch->pending)   /* a new load ended the check of the one before: its answer first */
            answer_pending(sv, ch);
        cl->pending = 1;
        ch->pending = 1;
        ch->pending_client = c->client_id;
        ch->pending_seq = c->seq;
        ch->pending_kind = c->kind;
        return;
    }
    cl->pending = 0;
    if (rc == 0 && c->kind == NCP_CMD_JOG && !(c->value[1] > 0))
        ch->jog_client = c->client_id;
    answer(sv, ch, a, c->client_id, c->seq, rc, why, c->kind == NCP_CMD_FILES);
}

/* The ACK of a command, with the state it leaves (it may change it at
 * once), and the status after it. */
static void answer(struct serve *sv, struct serve_channel *ch, ncp_ack_t *a, int32_t client,
                   int32_t seq, int rc, const char *why, int said)
{
    ncp_nck_poll(ch->nck);
    struct ncp_nck_snapshot st;
    ncp_nck_get_status(ch->nck, &st);
    a->utime = utime_now();
    a->client_id = client;
    a->seq = seq;
    a->channel = (int8_t)ch->num;
    a->result = rc == 0 ? NCP_ACK_T_ACCEPTED : NCP_ACK_T_REJECTED;
    a->state = (int8_t)st.state;
    /* an accepted FILES command answers with its path */
    snprintf((char *)a->reason, sizeof a->reason, "%s", rc == 0 && !said ? "" : why);
    send_ack(sv, a);
    send_status(sv, ch);
}

/* A command answered later: once its NCK has the answer, the ACK goes out
 * and its client's resends get the same one. */
static void answer_pending(struct serve *sv, struct serve_channel *ch)
{
    char why[sizeof ((ncp_ack_t *)0)->reason];
    int rc = ncp_nck_pending(ch->nck, why, sizeof why);
    if (rc == NCP_NCK_CMD_PENDING)
        return;
    ch->pending = 0;
    struct client *cl = client_of(sv, ch->pending_client, utime_now());
    const char *text;
    size_t len;
    if (rc == 0 && ch->pending_kind == NCP_CMD_LOAD && sv->hook && sv->hook->loaded &&
        ncp_nck_program_text(ch->nck, &text, &len) == 0) {
        struct ncp_nck_snapshot st;
        ncp_nck_get_status(ch->nck, &st);
        sv->hook->loaded(sv->hook->ctx, ch->num, st.program, text, len);
    }
    ncp_ack_t a;
    memset(&a, 0, sizeof a);
    answer(sv, ch, &a, ch->pending_client, ch->pending_seq, rc, why,
           ch->pending_kind == NCP_CMD_FILES);
    if (cl != NULL && cl->seq == ch->pending_seq) {
        cl->ack = a;
        cl->pending = 0;
    }
}

/* One channel's shutdown (a command, or a stop signal) is the service's:
 * every channel stops under control, and the service ends when all have. */
static int all_shut_down(struct serve *sv, int *spread)
{
    int all = 1, any = 0;
    for (int k = 0; k < sv->n_ch; k++) {
        int down = ncp_nck_shutdown_requested(sv->ch[k].nck);
        all &= down;
        any |= down;
    }
    if (any && !all && !*spread) {
        *spread = 1;
        for (int k = 0; k < sv->n_ch; k++)
            if (!ncp_nck_shutdown_requested(sv->ch[k].nck))
                ncp_nck_request_shutdown(sv->ch[k].nck);
    }
    return all;
}

int ncp_nck_serve_channels(struct ncp_nck *const *ncks, const int *nums, int n,
                           const struct ncp_nck_serve_opts *o, struct ncp_diag *d)
{
    if (n < 1 || n > NCP_NCK_CHANNELS_MAX)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "1..%d NC channels, not %d",
                            NCP_NCK_CHANNELS_MAX, n), -1;
    struct serve *sv = calloc(1, sizeof *sv);
    if (!sv)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory"), -1;
    for (int k = 0; k < n; k++)
        sv->ch[k] = (struct serve_channel){ .nck = ncks[k], .num = nums[k] };
    sv->n_ch = n;
    sv->hook = o->hook;
    /* the transport is one for all: the first channel's machine INI says where */
    const struct ncp_machine_cfg *cfg = ncks[0]->core.cfg;
    const char *prefix = o->prefix && *o->prefix ? o->prefix : cfg->lcm.prefix;
    struct ncp_dist_msg_opts mo;
    if (ncp_dist_msg_opts(&cfg->lcm, &mo, d) != NCP_OK) {
        free(sv);
        return -1;
    }
    if (o->url && *o->url)
        mo.opts.url = o->url;
    mo.opts.prefix = prefix;
    mo.opts.create_key = 1;
    mo.opts.max_age_ms = 0;   /* commands carry their own deadline */
    if (ncp_msg_open(&sv->msg, &mo.opts, d) != 0) {
        free(sv);
        return -1;
    }
    /* STATUS_HZ 0: no periodic status (state changes and acks still send one) */
    double hz = cfg->lcm.status_hz;
    int64_t period = hz > 0 ? (int64_t)llround(1e9 / hz) : INT64_MAX / 4;
    int64_t next_status = hz > 0 ? ncp_mono_ns() : INT64_MAX / 2;
    int stopping = 0, spread = 0;
    if (o->ready)
        o->ready(o->ctx, prefix);
    while (!all_shut_down(sv, &spread)) {
        if (!stopping && o->stop_requested && o->stop_requested(o->ctx)) {
            stopping = 1;
            for (int k = 0; k < n; k++)
                ncp_nck_request_shutdown(sv->ch[k].nck);
        }
        int64_t now = ncp_mono_ns();
        int64_t wait_ms = (next_status - now) / 1000000;
        if (wait_ms > 5)
            wait_ms = 5;   /* the NCK is polled at least every 5 ms */
        if (wait_ms < 0)
            wait_ms = 0;
        if (ncp_msg_poll(sv->msg, (int)wait_ms, on_command, sv) < 0) {
            ncp_diag_set(d, NCP_ERR_IO, 0, 0, "LCM socket failed");
            break;
        }
        /* the other front end's commands take the same path as LCM's */
        ncp_command_t hc;
        while (sv->hook && sv->hook->next_command && sv->hook->next_command(sv->hook->ctx, &hc))
            take_command(sv, &hc, 1);
        now = ncp_mono_ns();
        int due = now >= next_status;
        for (int k = 0; k < n; k++) {
            if (sv->ch[k].pending)
                answer_pending(sv, &sv->ch[k]);
            int changed = ncp_nck_poll(sv->ch[k].nck);
            send_events(sv, &sv->ch[k]);
            if (changed || due)
                send_status(sv, &sv->ch[k]);
        }
        if (n > 1)
            fault_stops_others(sv);
        if (due) {
            next_status += period;
            if (next_status < now)   /* fell behind: no burst to catch up */
                next_status = now + period;
        }
    }
    for (int k = 0; k < n; k++) {
        send_events(sv, &sv->ch[k]);
        send_status(sv, &sv->ch[k]);
    }
    int fault = sv->fault_seen;
    ncp_msg_close(sv->msg);
    free(sv->clients);
    free(sv);
    return fault ? 1 : 0;
}

int ncp_nck_serve(struct ncp_nck *nck, const struct ncp_nck_serve_opts *o, struct ncp_diag *d)
{
    int zero = 0;
    return ncp_nck_serve_channels(&nck, &zero, 1, o, d);
}
