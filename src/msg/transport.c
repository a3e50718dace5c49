/* The NCK's end of LCM's UDP multicast transport: one socket joined to the
 * group, shared with every other LCM process on the host exactly as liblcm
 * shares it (SO_REUSEADDR, SO_REUSEPORT, multicast loop on), so cnc-ctl,
 * lcm-spy and lcm-logger on the same machine see what the NCK sends and it
 * sees what they send.
 *
 * Receiving reads into one buffer of the largest UDP datagram; sending
 * encodes into another. Nothing is allocated after ncp_msg_open. */
#include <arpa/inet.h>
#include <errno.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "msg_int.h"
#include "ncpar/auth.h"
#include "ncpar/msg.h"

/* At most this many datagrams per ncp_msg_poll: a flood on the group must
 * not keep the service thread from its other work (the rest wait in the
 * socket's buffer, or the kernel drops them). */
#define POLL_DATAGRAMS_MAX 256

#define CHANNEL_SIZE (NCP_MSG_PREFIX_MAX + 8)
#define UDP_DATAGRAM_MAX 65536
/* header + the largest type (accdec_burst_t) + the MAC's trailer */
#define SEND_BUF_SIZE (8192 + NCP_AUTH_TRAILER_BYTES)
#define SUBS_MAX 32
/* Held back by INJECT_DELAY_US: our own messages are far smaller than this;
 * a larger one is passed on undelayed (and counted) rather than cut. */
#define DELAY_SLOTS 256
#define DELAY_BYTES 768

struct delayed {
    int64_t due_ns;
    int sub;
    uint16_t len;
    uint8_t data[DELAY_BYTES];
};

struct ncp_msg {
    int fd;
    int n_subs;
    char subs[SUBS_MAX][NCP_MSG_CHANNEL_MAX + 1];
    struct ncp_msg_inject inj;
    /* one per channel: a channel's losses do not depend on how much other
     * traffic (statuses, clock probes, heartbeats) came in between */
    struct ncp_msg_dice dice[SUBS_MAX];
    unsigned dq_head, dq_count;   /* FIFO: one delay for all, so due times ascend */
    struct delayed *dq;
    struct sockaddr_in group;
    uint32_t seqno; /* LC02 sequence number of the next datagram sent */
    char ch_cmd[CHANNEL_SIZE], ch_ack[CHANNEL_SIZE], ch_status[CHANNEL_SIZE],
        ch_event[CHANNEL_SIZE];
    struct ncp_msg_stats stats;
    struct ncp_auth *auth;
    int encrypt_public;   /* STATUS and EVENT encrypted ([LCM] STATUS_NEEDS_KEY) */
    int64_t max_age_ns;   /* ncp_msg_take: older datagrams are stale (0: no limit) */
    uint8_t sbuf[SEND_BUF_SIZE];
    uint8_t rbuf[UDP_DATAGRAM_MAX];
};

/* The socket as liblcm's udpm sets up its own (receive and send in one),
 * but bound to the group and joined on one interface only ([LCM] INTERFACE):
 * a datagram sent to this host's own address, or arriving on another
 * interface, never reaches it (IP_MULTICAST_ALL off: not even when another
 * program joined the group there). */
static int open_socket(struct ncp_msg *m, const struct ncp_msg_url *u, const char *ifname,
                       struct ncp_diag *d)
{
    unsigned ifindex = 0;
    if (ifname && *ifname && (ifindex = if_nametoindex(ifname)) == 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "[LCM] INTERFACE = %s: no such network interface (ip link lists them)",
                            ifname);
    int one = 1;
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot open a UDP socket for LCM: %s",
                            strerror(errno));
    m->fd = fd;
    if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "cannot share UDP port %u with other LCM processes: %s", u->port,
                            strerror(errno));
#ifdef SO_REUSEPORT
    /* liblcm sets it where SO_REUSEADDR alone does not share a port (BSD,
     * macOS); on Linux SO_REUSEADDR suffices and this is harmless. */
    (void)setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one);
#endif
    if (u->recv_buf_size > 0 &&
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &u->recv_buf_size, sizeof u->recv_buf_size) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot set the receive buffer to %d bytes: %s",
                            u->recv_buf_size, strerror(errno));
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_addr = ifindex ? m->group.sin_addr : (struct in_addr){ htonl(INADDR_ANY) };
    addr.sin_port = htons(u->port);
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "cannot bind UDP port %u for LCM: %s (another program that uses "
                            "the port without sharing it?)",
                            u->port, strerror(errno));
    struct ip_mreqn mreq;
    memset(&mreq, 0, sizeof mreq);
    mreq.imr_multiaddr = m->group.sin_addr;
    mreq.imr_address.s_addr = htonl(INADDR_ANY);
    mreq.imr_ifindex = (int)ifindex;
    int all = 0;
    if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "cannot join multicast group %s on port %u%s%s: %s (is there a "
                            "multicast route? see docs/operator.md: LCM and multicast)",
                            u->group, u->port, ifindex ? " on " : "", ifindex ? ifname : "",
                            strerror(errno));
    if (ifindex && (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &mreq, sizeof mreq) < 0 ||
                    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_ALL, &all, sizeof all) < 0))
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot keep LCM on interface %s: %s", ifname,
                            strerror(errno));
    unsigned char ttl = (unsigned char)u->ttl, loop = 1;
    if (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) < 0 ||
        setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "cannot set multicast ttl %d and loopback on group %s: %s", u->ttl,
                            u->group, strerror(errno));
    return NCP_OK;
}

int ncp_msg_open(struct ncp_msg **mp, const struct ncp_msg_opts *o, struct ncp_diag *d)
{
    *mp = NULL;
    const char *url = o->url, *prefix = o->prefix;
    if (url == NULL || url[0] == 0) {
        url = getenv("LCM_DEFAULT_URL");
        if (url == NULL || url[0] == 0)
            url = NCP_MSG_DEFAULT_URL;
    }
    if (prefix == NULL)
        prefix = NCP_MSG_DEFAULT_PREFIX;
    if (strlen(prefix) > NCP_MSG_PREFIX_MAX)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "LCM channel prefix '%s' is longer than %d characters", prefix,
                            NCP_MSG_PREFIX_MAX);
    struct ncp_msg_url u;
    int rc = ncp_msg_parse_url(url, &u, d);
    if (rc != NCP_OK)
        return rc;
    if (u.recv_buf_size == 0)
        u.recv_buf_size = o->recv_buf_default;
    if (o->key_file == NULL || *o->key_file == 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "LCM without a key file: refused");
    struct ncp_auth *auth = ncp_auth_open(o->key_file, NULL, o->create_key, d);
    if (auth == NULL)
        return NCP_ERR_IO;
    struct ncp_msg *m = calloc(1, sizeof *m);
    if (m == NULL) {
        ncp_auth_free(auth);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the LCM transport");
    }
    m->auth = auth;
    m->fd = -1;
    m->encrypt_public = o->encrypt_public;
    m->max_age_ns = (int64_t)o->max_age_ms * 1000000;
    m->group.sin_family = AF_INET;
    m->group.sin_port = htons(u.port);
    (void)inet_pton(AF_INET, u.group, &m->group.sin_addr);
    snprintf(m->ch_cmd, sizeof m->ch_cmd, "%sCMD", prefix);
    snprintf(m->ch_ack, sizeof m->ch_ack, "%sACK", prefix);
    snprintf(m->ch_status, sizeof m->ch_status, "%sSTATUS", prefix);
    snprintf(m->ch_event, sizeof m->ch_event, "%sEVENT", prefix);
    rc = open_socket(m, &u, o->interface, d);
    if (rc != NCP_OK) {
        ncp_msg_close(m);
        return rc;
    }
    *mp = m;
    return NCP_OK;
}

void ncp_msg_close(struct ncp_msg *m)
{
    if (m == NULL)
        return;
    if (m->fd >= 0)
        close(m->fd);
    ncp_auth_free(m->auth);
    free(m->dq);
    free(m);
}

int ncp_msg_fd(const struct ncp_msg *m)
{
    return m->fd;
}

void ncp_msg_get_stats(const struct ncp_msg *m, struct ncp_msg_stats *st)
{
    *st = m->stats;
}

/* One datagram: a command handed on (1), or not (0). */
static int take_datagram(struct ncp_msg *m, size_t len,
                         void (*on_cmd)(void *ctx, const ncp_command_t *cmd), void *ctx)
{
    const char *channel;
    const uint8_t *payload;
    size_t plen;
    m->stats.received++;
    if (ncp_msg_parse_datagram(m->rbuf, len, &channel, &payload, &plen) != 0) {
        /* A fragment is LCM's own business unless it claims to carry a
         * command (a command always fits one datagram); anything else that
         * is not LCM at all is garbage. */
        if (ncp_msg_is_fragment(m->rbuf, len)) {
            const char *fch = ncp_msg_fragment_channel(m->rbuf, len);
            if (fch != NULL && strcmp(fch, m->ch_cmd) == 0)
                m->stats.garbage++;
        } else {
            m->stats.garbage++;
        }
        return 0;
    }
    if (strcmp(channel, m->ch_cmd) != 0)
        return 0;
    /* nothing unauthenticated is decoded, let alone answered */
    int64_t sent_ns;
    if (ncp_auth_check(m->auth, channel, (uint8_t *)payload, plen, &plen, &sent_ns) !=
        NCP_AUTH_OK) {
        m->stats.auth_failed++;
        return 0;
    }
    ncp_command_t cmd;
    if (ncp_msg_decode_command(payload, plen, &cmd) != 0) {
        m->stats.garbage++;
        return 0;
    }
    m->stats.commands++;
    if (on_cmd)
        on_cmd(ctx, &cmd);
    return 1;
}

int ncp_msg_poll(struct ncp_msg *m, int timeout_ms,
                 void (*on_cmd)(void *ctx, const ncp_command_t *cmd), void *ctx)
{
    struct pollfd p = {.fd = m->fd, .events = POLLIN};
    int r = poll(&p, 1, timeout_ms);
    if (r < 0)
        return errno == EINTR ? 0 : -1;
    if (r == 0)
        return 0;
    int handed = 0;
    for (int i = 0; i < POLL_DATAGRAMS_MAX; i++) {
        ssize_t n = recv(m->fd, m->rbuf, sizeof m->rbuf, MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)
                break;
            return -1;
        }
        handed += take_datagram(m, (size_t)n, on_cmd, ctx);
    }
    return handed;
}

/* Seals and sends the header already in sbuf plus its encoded payload (n <
 * 0: the encoding failed; the encoders are given room for the trailer).
 * Never blocks: a full socket buffer is a send error. */
static int send_frame(struct ncp_msg *m, const char *channel, int header, int n, int encrypt)
{
    if (header < 0 || n < 0) {
        m->stats.send_errors++;
        return -1;
    }
    n = (int)ncp_auth_seal(m->auth, channel, m->sbuf + header, (size_t)n, encrypt,
                           ncp_auth_now_ns());
    ssize_t sent = sendto(m->fd, m->sbuf, (size_t)header + (size_t)n, MSG_DONTWAIT,
                          (const struct sockaddr *)&m->group, sizeof m->group);
    if (sent < 0) {
        m->stats.send_errors++;
        return -1;
    }
    m->seqno++;
    m->stats.sent++;
    return 0;
}

/* what an encoder may fill after a header of h bytes: the trailer follows */
#define ROOM(h) ((int)sizeof m->sbuf - (h) - (int)NCP_AUTH_TRAILER_BYTES)

int ncp_msg_send_ack(struct ncp_msg *m, const ncp_ack_t *a)
{
    int h = ncp_msg_frame_header(m->sbuf, sizeof m->sbuf, m->seqno, m->ch_ack);
    int n = h < 0 ? -1 : ncp_ack_t_encode(m->sbuf, h, ROOM(h), a);
    return send_frame(m, m->ch_ack, h, n, 0);
}

int ncp_msg_send_status(struct ncp_msg *m, const ncp_status_t *s)
{
    int h = ncp_msg_frame_header(m->sbuf, sizeof m->sbuf, m->seqno, m->ch_status);
    int n = h < 0 ? -1 : ncp_status_t_encode(m->sbuf, h, ROOM(h), s);
    return send_frame(m, m->ch_status, h, n, m->encrypt_public);
}

int ncp_msg_send_event(struct ncp_msg *m, const ncp_event_t *e)
{
    int h = ncp_msg_frame_header(m->sbuf, sizeof m->sbuf, m->seqno, m->ch_event);
    int n = h < 0 ? -1 : ncp_event_t_encode(m->sbuf, h, ROOM(h), e);
    return send_frame(m, m->ch_event, h, n, m->encrypt_public);
}

/* ---- any channel: the distributed mode's subscriptions ------------------- */

/* The channel's dice: seeded by INJECT_SEED and the channel's name (FNV-1a),
 * not by the order of the subscriptions. */
static void channel_dice(struct ncp_msg *m, int sub)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (const char *c = m->subs[sub]; *c; c++)
        h = (h ^ (unsigned char)*c) * 0x100000001b3ull;
    ncp_msg_dice_seed(&m->dice[sub], m->inj.seed ^ h);
}

int ncp_msg_subscribe(struct ncp_msg *m, const char *channel)
{
    size_t n = strlen(channel);
    if (m->n_subs >= SUBS_MAX || n == 0 || n > NCP_MSG_CHANNEL_MAX)
        return -1;
    memcpy(m->subs[m->n_subs], channel, n + 1);
    channel_dice(m, m->n_subs);
    return m->n_subs++;
}

int ncp_msg_set_inject(struct ncp_msg *m, const struct ncp_msg_inject *in)
{
    if (in->delay_ns > 0 && m->dq == NULL) {
        m->dq = calloc(DELAY_SLOTS, sizeof *m->dq);
        if (m->dq == NULL)
            return -1;
    }
    m->inj = *in;
    for (int i = 0; i < m->n_subs; i++)
        channel_dice(m, i);
    return 0;
}

int ncp_msg_publish(struct ncp_msg *m, const char *channel, const void *payload, size_t len)
{
    int h = ncp_msg_frame_header(m->sbuf, sizeof m->sbuf, m->seqno, channel);
    if (h < 0 || len > sizeof m->sbuf - (size_t)h - NCP_AUTH_TRAILER_BYTES) {
        m->stats.send_errors++;
        return -1;
    }
    memcpy(m->sbuf + h, payload, len);
    int rc = send_frame(m, channel, h, (int)len, 0);
    if (rc == 0) {
        m->stats.sent_bytes += (uint64_t)h + len + NCP_AUTH_TRAILER_BYTES;
        m->stats.sent_payload_bytes += len + NCP_AUTH_TRAILER_BYTES;
    }
    return rc;
}

static int sub_index(const struct ncp_msg *m, const char *channel)
{
    for (int i = 0; i < m->n_subs; i++)
        if (strcmp(m->subs[i], channel) == 0)
            return i;
    return -1;
}

/* The oldest held-back datagram when it is due: 1 with *sub, *p, *len set. */
static int take_due(struct ncp_msg *m, int64_t now_ns, int *sub, const uint8_t **p, size_t *len)
{
    if (m->dq_count == 0 || m->dq[m->dq_head].due_ns > now_ns)
        return 0;
    struct delayed *e = &m->dq[m->dq_head];
    m->dq_head = (m->dq_head + 1) % DELAY_SLOTS;
    m->dq_count--;
    *sub = e->sub;
    *p = e->data;
    *len = e->len;
    return 1;
}

/* A datagram on a subscribed channel that is not ncpar's (no key, or a
 * forged or changed one), or from too long ago (a recording played back):
 * counted, and as if it had not come. */
static int refused(struct ncp_msg *m, const char *channel, uint8_t *p, size_t *plen,
                   int64_t *real_now)
{
    int64_t sent_ns;
    if (ncp_auth_check(m->auth, channel, p, *plen, plen, &sent_ns) != NCP_AUTH_OK) {
        m->stats.auth_failed++;
        return 1;
    }
    if (m->max_age_ns > 0) {
        if (*real_now == 0)
            *real_now = ncp_auth_now_ns();
        int64_t age = *real_now - sent_ns;
        if (age > m->max_age_ns || age < -m->max_age_ns) {
            m->stats.stale++;
            return 1;
        }
    }
    return 0;
}

int ncp_msg_take(struct ncp_msg *m, int64_t now_ns, int *sub, const uint8_t **payload,
                 size_t *len)
{
    if (take_due(m, now_ns, sub, payload, len))
        return 1;
    int64_t real_now = 0;   /* read once per call, when a datagram needs it */
    for (int i = 0; i < POLL_DATAGRAMS_MAX; i++) {
        ssize_t n = recv(m->fd, m->rbuf, sizeof m->rbuf, MSG_DONTWAIT);
        if (n < 0)
            return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : -1;
        m->stats.received++;
        const char *channel;
        const uint8_t *p;
        size_t plen;
        if (ncp_msg_parse_datagram(m->rbuf, (size_t)n, &channel, &p, &plen) != 0) {
            m->stats.garbage += !ncp_msg_is_fragment(m->rbuf, (size_t)n);
            continue;
        }
        int s = sub_index(m, channel);
        if (s < 0)
            continue;   /* other LCM traffic on the group */
        if (refused(m, channel, (uint8_t *)p, &plen, &real_now))
            continue;
        m->stats.taken++;
        m->stats.taken_bytes += (uint64_t)n;
        if (m->inj.loss > 0 && ncp_msg_dice_drop(&m->dice[s], m->inj.loss)) {
            m->stats.inject_lost++;
            continue;
        }
        if (m->inj.delay_ns > 0 && m->dq != NULL) {
            if (plen > DELAY_BYTES || m->dq_count == DELAY_SLOTS) {
                m->stats.inject_undelayed++;
            } else {
                struct delayed *e = &m->dq[(m->dq_head + m->dq_count) % DELAY_SLOTS];
                e->due_ns = now_ns + m->inj.delay_ns;
                e->sub = s;
                e->len = (uint16_t)plen;
                memcpy(e->data, p, plen);
                m->dq_count++;
                m->stats.inject_delayed++;
                continue;
            }
        }
        *sub = s;
        *payload = p;
        *len = plen;
        return 1;
    }
    return 0;
}

/* xorshift64*: a few instructions per message, the same losses for the same
 * seed on every machine. */
void ncp_msg_dice_seed(struct ncp_msg_dice *d, uint64_t seed)
{
    /* xorshift's state must not be 0 */
    d->s = (seed * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull) | 1u;
}

int ncp_msg_dice_drop(struct ncp_msg_dice *d, double fraction)
{
    d->s ^= d->s >> 12;
    d->s ^= d->s << 25;
    d->s ^= d->s >> 27;
    uint64_t r = d->s * 0x2545F4914F6CDD1Dull;
    return (double)(r >> 11) * (1.0 / 9007199254740992.0) < fraction;
}
