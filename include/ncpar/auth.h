/* Who may command the machine: one shared secret (the key file) and a MAC on
 * every LCM message that can move or change the machine.
 *
 * Every message ncpar sends on LCM carries a trailer after its lcm-gen
 * encoding, so LCM's own tools (lcm-spy, lcm-logger) still decode it:
 *
 *   magic[4]   "NCA1" (plain) or "NCE1" (the encoding is encrypted)
 *   sent_ns    int64, big-endian: the sender's CLOCK_REALTIME, strictly
 *              increasing per sender (one nonce never serves twice)
 *   salt       uint32, big-endian: random per sender process
 *   mac[16]    HMAC-SHA256(key, "ncpar-lcm-1" NUL channel NUL encoding
 *              magic sent_ns salt), its first 16 bytes
 *
 * The channel is inside the MAC, so a message cannot be moved from one
 * channel to another (an ACK replayed as a command). "NCE1" encodings are
 * ChaCha20-encrypted under a key derived from the same secret, nonce
 * (sent_ns, salt), then MACed ([LCM] STATUS_NEEDS_KEY for status and events).
 *
 * Freshness (a command's deadline) and replay (sequence numbers) are the
 * receiver's business: src/nck/service.c for commands, the LLC's sequence
 * checks and the transport's age limit for the distributed NCK.
 *
 * The key file: 32 random bytes (or their 64 hex digits), mode 0600, in a
 * folder of mode 0700. Sealing and checking allocate nothing and make no
 * system call (the position loops of the distributed NCK call them). */
#ifndef NCPAR_AUTH_H
#define NCPAR_AUTH_H

#include <stddef.h>
#include <stdint.h>

#include "ncpar/diag.h"

#define NCP_AUTH_KEY_BYTES 32
#define NCP_AUTH_MAC_BYTES 16
#define NCP_AUTH_TRAILER_BYTES (4 + 8 + 4 + NCP_AUTH_MAC_BYTES)
#define NCP_AUTH_PATH_MAX 512

struct ncp_auth;

/* ---- the key file (blocking: before any real-time thread) --------------- */

/* The key file to use: explicit (--key-file) if given, else ini ([LCM]
 * KEY_FILE) if not empty, else $XDG_CONFIG_HOME/ncpar/lcm.key, else
 * $HOME/.config/ncpar/lcm.key. 0, or -1 with d set (no HOME, too long). */
int ncp_auth_key_path(char *buf, size_t size, const char *explicit_path, const char *ini,
                      struct ncp_diag *d);

/* Reads the key at path. create: make it (32 bytes from getrandom, 0600, its
 * folder 0700) when it does not exist, as `serve` does. A file that group or
 * others may read or write, or that is not 32 bytes (or 64 hex digits), is
 * refused, naming the file and its mode. 0, or -1 with d set. */
int ncp_auth_load_key(const char *path, int create, uint8_t key[NCP_AUTH_KEY_BYTES],
                      struct ncp_diag *d);

/* A sealing and checking context for key (NULL: out of memory). The key's
 * copy is wiped on free. */
struct ncp_auth *ncp_auth_new(const uint8_t key[NCP_AUTH_KEY_BYTES]);
/* The context of the key file ncp_auth_key_path finds (made when create and
 * missing): the key is read, used and wiped here. NULL with d set. */
struct ncp_auth *ncp_auth_open(const char *explicit_path, const char *ini, int create,
                               struct ncp_diag *d);
void ncp_auth_free(struct ncp_auth *a);

/* ---- sealing and checking (no allocation, no system call) -------------- */

/* Appends the trailer to msg[0..len) (room for NCP_AUTH_TRAILER_BYTES more
 * must follow), encrypting the encoding first when encrypt is set. now_ns:
 * CLOCK_REALTIME. Returns the sealed length. Not thread-safe per context
 * (its sent_ns is the sender's): one context per sending thread. */
size_t ncp_auth_seal(struct ncp_auth *a, const char *channel, uint8_t *msg, size_t len,
                     int encrypt, int64_t now_ns);

enum ncp_auth_verdict {
    NCP_AUTH_OK = 0,
    NCP_AUTH_NO_TRAILER = -1,  /* too short, or no known magic: a keyless sender */
    NCP_AUTH_BAD_MAC = -2,     /* forged or tampered */
};
/* Checks msg[0..len) sealed on channel: NCP_AUTH_OK with *body_len (the
 * encoding's length, decrypted in place when it was encrypted) and *sent_ns,
 * or a verdict < 0 (msg unchanged). Comparison in constant time. */
enum ncp_auth_verdict ncp_auth_check(const struct ncp_auth *a, const char *channel, uint8_t *msg,
                                     size_t len, size_t *body_len, int64_t *sent_ns);

/* CLOCK_REALTIME in ns (the clock sent_ns and deadlines are on). */
int64_t ncp_auth_now_ns(void);

#endif
