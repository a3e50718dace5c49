/* LCM messaging of a serving NCK: the generated types of lcm/ncp_*.lcm (lcm-gen at
 * build time, fixed-size) over LCM's UDP multicast protocol ("udpm://"), so
 * lcm-spy, lcm-logger and any LCM client see and send the same messages.
 *
 * The NCK's side is its own small transport rather than liblcm: it links into
 * the static cnc-run, receives into one fixed buffer (a flood of datagrams
 * allocates nothing) and counts what it cannot use. Channels are
 * <prefix>CMD (in), <prefix>ACK, <prefix>STATUS and <prefix>EVENT (out).
 * Not for the real-time threads: the service thread calls it.
 *
 * Every datagram sent is sealed with the key (ncpar/auth.h); every datagram
 * taken in (a command, a subscribed channel) must carry a valid seal, else it
 * is dropped and counted (auth_failed) before anything decodes it. */
#ifndef NCPAR_MSG_H
#define NCPAR_MSG_H

#include <stddef.h>
#include <stdint.h>

#include "ncpar/diag.h"
#include "ncp_ack_t.h"
#include "ncp_command_t.h"
#include "ncp_event_t.h"
#include "ncp_status_t.h"

#define NCP_MSG_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"
#define NCP_MSG_DEFAULT_PREFIX "NCP_"
#define NCP_MSG_PREFIX_MAX 32

struct ncp_msg;

struct ncp_msg_stats {
    uint64_t received;    /* datagrams read */
    uint64_t commands;    /* valid commands handed on */
    uint64_t garbage;     /* on <prefix>CMD, or unreadable at all: bad magic,
                             truncated, wrong fingerprint, bad fields */
    uint64_t auth_failed; /* on a channel taken in, without the key's valid MAC:
                             keyless, forged or tampered; never decoded */
    uint64_t stale;       /* ncp_msg_take: sealed longer ago than max_age_ms */
    uint64_t sent, send_errors;
    /* ncp_msg_take's channels (the distributed mode) */
    uint64_t taken, taken_bytes;       /* datagrams on a subscribed channel, with headers */
    uint64_t sent_bytes, sent_payload_bytes; /* by ncp_msg_publish: datagrams, payloads */
    uint64_t inject_lost;              /* dropped by INJECT_LOSS */
    uint64_t inject_delayed;           /* held back by INJECT_DELAY_US */
    uint64_t inject_undelayed;         /* too large or no room to hold back: passed on */
};

struct ncp_msg_opts {
    /* NULL or "": $LCM_DEFAULT_URL, else NCP_MSG_DEFAULT_URL. Only udpm://
     * is understood (host must be a multicast group; ?ttl=N, ?recv_buf_size=N). */
    const char *url;
    const char *prefix;      /* NULL: NCP_MSG_DEFAULT_PREFIX */
    const char *key_file;    /* required: ncp_auth_key_path's choice */
    int create_key;          /* make the key file when it does not exist (the NCK) */
    /* [LCM] INTERFACE: the group is joined on this interface only and the
     * socket bound to the group; NULL or "": any (the route decides) */
    const char *interface;
    int encrypt_public;      /* [LCM] STATUS_NEEDS_KEY: STATUS and EVENT encrypted */
    int max_age_ms;          /* ncp_msg_take drops datagrams sealed longer ago or
                                further ahead than this (0: no limit) */
    int recv_buf_default;    /* receive buffer (bytes) where the URL names none;
                                0: the system's default. The kernel caps it at
                                net.core.rmem_max. */
};

/* Opens the transport with the key of o->key_file. On error d->msg says why. */
int ncp_msg_open(struct ncp_msg **m, const struct ncp_msg_opts *o, struct ncp_diag *d);
void ncp_msg_close(struct ncp_msg *m);

/* Waits up to timeout_ms (0: only what is queued) and hands every valid
 * command on <prefix>CMD to on_cmd, in arrival order. Messages on other
 * channels are skipped silently (other NCKs and tools share the group).
 * Returns the number of commands handed on, or -1 on a socket error. */
int ncp_msg_poll(struct ncp_msg *m, int timeout_ms,
                 void (*on_cmd)(void *ctx, const ncp_command_t *cmd), void *ctx);

int ncp_msg_send_ack(struct ncp_msg *m, const ncp_ack_t *a);
int ncp_msg_send_status(struct ncp_msg *m, const ncp_status_t *s);
int ncp_msg_send_event(struct ncp_msg *m, const ncp_event_t *e);

void ncp_msg_get_stats(const struct ncp_msg *m, struct ncp_msg_stats *st);

/* The socket, for a caller that waits on it beside others (POLLIN: call
 * ncp_msg_poll with timeout 0). */
int ncp_msg_fd(const struct ncp_msg *m);

/* ---- any channel (the distributed mode, the distributed-NCK paper) ------------------------
 * Several channels on one socket; encoded payloads in and out. What comes in
 * may be lost or delayed on purpose ([LCM] INJECT_*): on the receiving side,
 * so each receiver has its own losses and counts them. Nothing here blocks:
 * the position loops of cnc-axis and of the lcm backend call it directly. */
#define NCP_MSG_CHANNEL_MAX 63

/* A channel to take (exact name): its index, or -1 when there are already
 * 32 or the name is not a channel name. Before the real-time loop. */
int ncp_msg_subscribe(struct ncp_msg *m, const char *channel);
/* Frames and sends payload on channel without blocking: 0, or -1 (counted). */
int ncp_msg_publish(struct ncp_msg *m, const char *channel, const void *payload, size_t len);
/* The next datagram on a subscribed channel (after injected loss and delay):
 * 1 with *sub and the payload set (valid until the next call), 0 when none
 * is waiting (at most 256 are read per call), -1 on a socket error. now_ns:
 * CLOCK_MONOTONIC, for the injected delay. */
int ncp_msg_take(struct ncp_msg *m, int64_t now_ns, int *sub, const uint8_t **payload,
                 size_t *len);

/* Seeded dice for the injected loss: the same seed loses the same messages
 * (ncp_msg_take throws one per subscribed channel, so the same ones of each
 * channel, whatever else came in between). */
struct ncp_msg_dice {
    uint64_t s;
};
void ncp_msg_dice_seed(struct ncp_msg_dice *d, uint64_t seed);
/* 1 with probability fraction. */
int ncp_msg_dice_drop(struct ncp_msg_dice *d, double fraction);

struct ncp_msg_inject {
    double loss;        /* fraction of incoming messages dropped, 0..1 */
    int64_t delay_ns;   /* every incoming message held back this long */
    uint64_t seed;
};
/* Before the real-time loop (allocates the delay queue): 0, or -1. */
int ncp_msg_set_inject(struct ncp_msg *m, const struct ncp_msg_inject *in);

/* Pure helpers (tested without a network). */
/* What a udpm:// URL says (LCM's syntax and defaults: udpm://239.255.76.67:7667,
 * ttl 0). 0 ok, else d->msg says why. */
struct ncp_msg_url {
    char group[16];      /* dotted quad, a multicast group */
    uint16_t port;
    int ttl;             /* 0: the messages stay on this host */
    int recv_buf_size;   /* bytes, 0: the system's default */
};
int ncp_msg_parse_url(const char *url, struct ncp_msg_url *u, struct ncp_diag *d);
/* Writes an LC02 header (magic, seqno, channel and its NUL) to buf: its
 * length (the payload follows), or -1 when it does not fit or the channel is
 * empty or longer than LCM's 63 characters. */
int ncp_msg_frame_header(uint8_t *buf, size_t size, uint32_t seqno, const char *channel);
/* One LCM datagram (LC02 short message): channel and payload, or -1 when it
 * is not one (bad magic, no NUL-terminated channel, fragment). */
int ncp_msg_parse_datagram(const uint8_t *buf, size_t len, const char **channel,
                           const uint8_t **payload, size_t *payload_len);
/* Decodes and validates a command (fingerprint, NUL in text, known kind,
 * client_id != 0). 0 ok, -1 garbage. */
int ncp_msg_decode_command(const uint8_t *payload, size_t len, ncp_command_t *cmd);

/* status_t's state constants by name ("idle", "running", "paused", "stepping",
 * "mdi", "jogging", "homing", "stopping", "estop", "fault"): NULL / -1 for
 * anything else. */
const char *ncp_msg_state_name(int state);
int ncp_msg_state_parse(const char *name);
/* status_t's estimate states (EST_ constants) by name: "none", "running",
 * "done", "failed", "cancelled"; NULL for anything else. */
const char *ncp_msg_estimate_name(int state);
/* status_t's llc_state (ax_status_t's states) by name: "unheard" (-1),
 * "waiting", "running", "stopping", "stopped", "fault", "done"; NULL for
 * anything else. */
const char *ncp_msg_llc_state_name(int state);
/* status_t's llc_error (LLC_ERR_ constants) as the operator reads it in a
 * few words ("setpoints lost", "following error", "unheard (killed or cut
 * off)", ...): "" for none (0), NULL for anything unknown. The whole text
 * is the event that told it. */
const char *ncp_msg_llc_error_name(int error);
/* event_t's kinds by name ("info", "msg", "debug", "print", "error",
 * "fault"): NULL for anything else. */
const char *ncp_msg_event_kind_name(int kind);
/* A status as one JSON object (no newline), the keys of `cnc-ctl status
 * --json`. Returns its length, or -1 when size is too small (8192 is enough). */
int ncp_msg_status_json(const ncp_status_t *s, char *buf, size_t size);
/* An event as one JSON object (no newline): kind, channel, seq, utime,
 * file, line, col, text, what `cnc-ctl events --json` prints. Its length, or
 * -1 when size is too small (2048 is enough). */
int ncp_msg_event_json(const ncp_event_t *e, char *buf, size_t size);
/* A modal code (code*10, as in the status's gcodes and mcodes: 911 -> "G91.1")
 * into buf: its length, or -1 for none (< 0) or no room. */
int ncp_msg_code_name(char letter, int code10, char *buf, size_t size);
/* The status's modal codes in force, G then M, space-separated, G64 with its
 * P and Q when set ("G1 G17 ... G64 P0.01 Q0 ... M5 M9 M48"): length, or -1
 * when buf is too small. */
int ncp_msg_active_codes_text(const ncp_status_t *s, char *buf, size_t size);

#endif
