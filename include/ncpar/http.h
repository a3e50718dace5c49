/* The operator's panel in the browser: `cnc-run serve --http [ADDR:]PORT`.
 * An HTTP server (libwebsockets) on a thread of its own, never a real-time
 * one, serves the panel's files and a WebSocket. The socket carries the
 * NCK's STATUS, EVENTs and ACKs out as JSON and takes commands in as JSON,
 * turned into the LCM command type and handed to the serving thread through
 * ncp_nck_serve_hook: one command path for LCM and the browser.
 *
 * A token drawn at start (printed with the panel's address) must be in the
 * socket's URL (?token=...) for any command; without it the socket shows the
 * status only. Bad input is refused, counted (ncp_http_stats) and never
 * reaches the NCK.
 *
 * A program is uploaded into the NCK's program folder (its working
 * directory) by POST /upload?token=...&name=NAME[&overwrite=1] with the file
 * as the body; the answer is JSON {"ok": true, "name": ...} or {"ok": false,
 * "reason": ...}. Loading it is then an ordinary load command. */
#ifndef NCPAR_HTTP_H
#define NCPAR_HTTP_H

#include <stddef.h>
#include <stdint.h>

#include "ncpar/diag.h"
#include "ncpar/msg.h"
#include "ncpar/nck.h"

#define NCP_HTTP_TOKEN_LEN 32       /* hex digits */
#define NCP_HTTP_MSG_MAX 4096       /* largest message taken in */
#define NCP_HTTP_UPLOAD_MAX (4u << 20) /* largest program uploaded (what the panel shows) */
#define NCP_HTTP_UPLOAD_NAME_MAX 100

struct ncp_http_opts {
    char addr[64];                  /* numeric IPv4/IPv6 address to listen on */
    int port;
    int readonly;                   /* status only: every command refused */
    const char *web_root;           /* the panel's files */
    const char *self_exe;           /* cnc-run, for the preview's `parse --canon` */
};

/* Counters of the socket's input (all since start). */
struct ncp_http_stats {
    uint64_t connections, commands;      /* commands handed to the NCK */
    uint64_t bad_json, unknown, oversized, flood, no_token, readonly, busy;
    uint64_t dropped;                    /* answers lost to a socket that does not read */
    uint64_t uploads, upload_bad;        /* programs stored; refused for their name, size
                                            or content (no token, read-only: counted above) */
    uint64_t status_sent, status_skipped; /* skipped: a slow client got a newer one */
};

/* Whether this build has the HTTP server (built with libwebsockets). */
int ncp_http_available(void);
/* "[ADDR:]PORT" (ADDR default 127.0.0.1; [v6]:PORT for IPv6) into o->addr and
 * o->port. 0, or -1 with d->msg. */
int ncp_http_parse_listen(const char *spec, struct ncp_http_opts *o, struct ncp_diag *d);

struct ncp_http;
/* Listens and starts the server's thread. NULL with d->msg on failure. */
struct ncp_http *ncp_http_start(const struct ncp_http_opts *o, struct ncp_diag *d);
void ncp_http_stop(struct ncp_http *h);
const char *ncp_http_token(const struct ncp_http *h);
/* The hook to put into ncp_nck_serve_opts (valid until ncp_http_stop). */
const struct ncp_nck_serve_hook *ncp_http_hook(struct ncp_http *h);
void ncp_http_get_stats(struct ncp_http *h, struct ncp_http_stats *st);

/* ---- pure helpers (unit-tested) ---------------------------------------------------- */

/* What one message from the browser asks for. */
enum ncp_http_req {
    NCP_HTTP_REQ_BAD = -1,      /* why says it (malformed, unknown command, bad field) */
    NCP_HTTP_REQ_COMMAND = 0,   /* an NCK command: *cmd is filled and validated */
    NCP_HTTP_REQ_LIST,          /* the programs in the NCK's folder */
    NCP_HTTP_REQ_PROGRAM,       /* the loaded program's text */
    NCP_HTTP_REQ_PREVIEW,       /* the loaded program's canonical commands */
};
/* Parses one message: a flat JSON object {"cmd": NAME, ...fields}. unknown is
 * set when the JSON was well formed but NAME is no command. */
enum ncp_http_req ncp_http_parse_request(const char *json, size_t len, int32_t client_id,
                                         ncp_command_t *cmd, int *unknown, char *why,
                                         size_t why_len);
/* Whether name may be an uploaded program's (a plain file name of letters,
 * digits and . _ - +, not starting with . or -, ending in .ngc, .nc or .tap):
 * 1, or 0 with why. */
int ncp_http_upload_name_ok(const char *name, char *why, size_t why_len);
/* s as a JSON string (quoted, escaped) appended to buf at *len; -1 if it
 * does not fit (buf then holds a truncated prefix). */
int ncp_http_json_string(char *buf, size_t size, size_t *len, const char *s, size_t n);

#endif
