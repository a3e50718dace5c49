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
    /* the machine INI's [HTTP] ALLOW_ORIGIN and ALLOW_HOST (NULL: none) */
    const char *allow_origin, *allow_host;
    /* put into every hello after its own fields (", \"limits\": ..."): the
     * machine's override limits and travel for the panel; NULL: none */
    const char *hello_extra;
    /* The program folder: where uploads land, what the program list shows
     * and where the panel's relative loads start (the machine INI's
     * [DISPLAY] PROGRAM_PREFIX, its first folder); NULL or "": serve's
     * working directory. */
    const char *program_dir;
    /* what the panel's Tools and History tabs read (channel 0's tool table
     * and [DISPLAY] HISTORY_FILE, as the NCK's FILES command names them);
     * NULL: the machine keeps none, and the tab says so */
    const char *tool_table, *history_file;
};

/* Counters of the socket's input (all since start). */
struct ncp_http_stats {
    uint64_t connections, commands;      /* commands handed to the NCK */
    uint64_t bad_json, unknown, oversized, flood, no_token, readonly, busy;
    uint64_t dropped;                    /* answers lost to a socket that does not read */
    uint64_t uploads, upload_bad;        /* programs stored; refused for their name, size
                                            or content (no token, read-only: counted above) */
    uint64_t status_sent, status_skipped; /* skipped: a slow client got a newer one */
    uint64_t foreign_origin, bad_host;   /* requests refused with 403, 421 */
    uint64_t bad_request;                /* ambiguous framing: 400, 411 */
    uint64_t unauth_closed;              /* sockets without the token closed (2 s, or
                                            evicted by a newer one) */
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
    NCP_HTTP_REQ_TOOLS,         /* the tool table file's text */
    NCP_HTTP_REQ_HISTORY,       /* the job history file's last lines */
    NCP_HTTP_REQ_GOT,           /* the panel has read a large answer's parts:
                                 * cmd->ivalue[0] its id, [1] how many */
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
/* name in the program folder dir (NULL or "": the working directory): dir/name,
 * or name itself when it is absolute or there is no folder. 0, or -1 when it
 * does not fit in cap. */
int ncp_http_program_path(const char *dir, const char *name, char *out, size_t cap);
/* s as a JSON string (quoted, escaped) appended to buf at *len; -1 if it
 * does not fit (buf then holds a truncated prefix). */
int ncp_http_json_string(char *buf, size_t size, size_t *len, const char *s, size_t n);

/* Who may talk to the panel at all (policy.c). A page's Origin must be the
 * panel's own (http:// and the request's Host) or one of ALLOW_ORIGIN; the
 * Host must name the panel: its bound address, a loopback name (localhost,
 * 127.0.0.1, [::1]), with the bound port or none, or one of ALLOW_HOST. A
 * rebinding attacker's page has neither. */
#define NCP_HTTP_ALLOW_MAX 16
#define NCP_HTTP_NAME_MAX 256
struct ncp_http_origin {
    int https;
    char host[NCP_HTTP_NAME_MAX];   /* lower case; IPv6 in brackets */
    int port;                       /* 0: not given */
};
struct ncp_http_policy {
    char addr[64];                  /* the bound address as a Host names it; "" for a
                                       wildcard (0.0.0.0, ::) */
    int port;
    struct ncp_http_origin allow_origin[NCP_HTTP_ALLOW_MAX], allow_host[NCP_HTTP_ALLOW_MAX];
    int n_allow_origin, n_allow_host;
};
/* The headers that decide whether a request is served at all: each one's
 * first value (NULL when absent) and how many times it came. */
struct ncp_http_head {
    const char *host, *origin, *content_length, *transfer_encoding;
    int n_host, n_origin, n_content_length, n_transfer_encoding;
};
/* The policy for a panel bound to addr:port with the INI's lists (space- or
 * comma-separated; NULL or "" for none): 0, or -1 with why naming the entry. */
int ncp_http_policy_init(struct ncp_http_policy *p, const char *addr, int port,
                         const char *allow_origin, const char *allow_host, char *why,
                         size_t why_len);
/* One ALLOW_ORIGIN or ALLOW_HOST list as the INI gives it: 0, or -1 with why
 * naming the first bad entry (the machine INI's check, before any socket). */
int ncp_http_allow_list_ok(const char *list, int origins, char *why, size_t why_len);
/* 0 when the request may go on (to the token check, the files, the socket);
 * else the HTTP status that refuses it, with why: 403 a foreign Origin
 * (checked first: nothing else of such a request is looked at), 421 a Host
 * that does not name the panel, 400 ambiguous framing (two Content-Lengths,
 * Content-Length with Transfer-Encoding, two Hosts), 411 a chunked body. */
int ncp_http_head_verdict(const struct ncp_http_policy *p, const struct ncp_http_head *h,
                          char *why, size_t why_len);

#endif
