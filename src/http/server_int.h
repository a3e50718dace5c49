/* src/http's private contract between the socket code (server.c) and the
 * panel's queries (query.c). */
#ifndef NCP_HTTP_SERVER_INT_H
#define NCP_HTTP_SERVER_INT_H

#include "ncpar/http.h"

#include <libwebsockets.h>

/* The panel's LCM client ids: a tag in the top bits, so its acks are told
 * from cnc-ctl's (whose ids are random) well enough for routing. */
#define NCP_HTTP_CLIENT_TAG ((int32_t)0x57000000)
#define NCP_HTTP_CLIENT_MASK ((int32_t)0x7f000000)
#define NCP_HTTP_STATUS_MAX 8192

struct conn;
/* Queues a message for one socket (copied). */
void ncp_http_send(struct ncp_http *h, struct conn *c, const char *msg, size_t len);
void ncp_http_refuse(struct ncp_http *h, struct conn *c, int32_t seq, const char *why);
/* The program list, the loaded program's text or its preview, answered on c. */
void ncp_http_answer_query(struct ncp_http *h, struct conn *c, enum ncp_http_req r,
                           const char *program);
const struct ncp_http_opts *ncp_http_opts_of(const struct ncp_http *h);

/* Whether the request's URL carries the token (?token=...). */
int ncp_http_token_ok(const struct ncp_http *h, struct lws *wsi);
enum ncp_http_stat {
    NCP_HTTP_STAT_NO_TOKEN, NCP_HTTP_STAT_READONLY, NCP_HTTP_STAT_OVERSIZED,
    NCP_HTTP_STAT_UPLOADS, NCP_HTTP_STAT_UPLOAD_BAD
};
void ncp_http_count(struct ncp_http *h, enum ncp_http_stat which);
/* POST /upload (upload.c): libwebsockets' callback and its session's size. */
int ncp_http_on_upload(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                       size_t len);
size_t ncp_http_upload_session_size(void);

#endif
