/* The gate: the callback libwebsockets gives every HTTP request and every
 * WebSocket upgrade first (the default protocol's). Origin, Host and the
 * request's framing are judged here (policy.c) before a file is served, a
 * token is looked at or an upload is begun; a refusal is answered with its
 * status and reason and the connection closed. */
#include "server_int.h"

#include <stdio.h>
#include <string.h>

#define VALUE_MAX 512

/* One header's first value into buf and how many times it came. A value too
 * long for buf is kept as "\x7f", which no check accepts. */
static int header(struct lws *wsi, enum lws_token_indexes t, char *buf, size_t size,
                  const char **value)
{
    int n = 0;
    *value = NULL;
    for (;; n++) {
        char tmp[VALUE_MAX];
        int r = lws_hdr_copy_fragment(wsi, tmp, (int)sizeof tmp, t, n);
        if (r < 0 && lws_hdr_fragment_length(wsi, t, n) <= 0)
            break;
        if (n == 0) {
            snprintf(buf, size, "%s", r < 0 ? "\x7f" : tmp);
            *value = buf;
        }
    }
    return n;
}

/* The status line with its reason (libwebsockets knows none for 421), a
 * JSON body as the upload's answers, and the end of the connection. */
static void refuse_http(struct lws *wsi, int status, const char *why)
{
    static const struct { int code; const char *text; } reasons[] = {
        { 400, "Bad Request" }, { 403, "Forbidden" }, { 411, "Length Required" },
        { 421, "Misdirected Request" },
    };
    const char *reason = "Refused";
    for (size_t i = 0; i < sizeof reasons / sizeof reasons[0]; i++)
        if (reasons[i].code == status)
            reason = reasons[i].text;
    char body[400];
    size_t n = (size_t)snprintf(body, sizeof body, "{\"ok\": false, \"reason\": ");
    ncp_http_json_string(body, sizeof body - 3, &n, why, strlen(why));
    body[n++] = '}';
    body[n++] = '\n';
    unsigned char buf[LWS_PRE + 1024];
    unsigned char *start = buf + LWS_PRE, *p = start, *end = buf + sizeof buf - 1;
    char line[64], len[24];
    int k = snprintf(line, sizeof line, "HTTP/1.1 %d %s", status, reason);
    int m = snprintf(len, sizeof len, "%zu", n);
    if (lws_add_http_header_by_name(wsi, NULL, (unsigned char *)line, k, &p, end) ||
        lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CONTENT_TYPE,
                                     (unsigned char *)"application/json", 16, &p, end) ||
        lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH, (unsigned char *)len,
                                     m, &p, end) ||
        lws_add_http_header_by_token(wsi, WSI_TOKEN_CONNECTION, (unsigned char *)"close", 5,
                                     &p, end) ||
        lws_finalize_http_header(wsi, &p, end) || (size_t)(end - p) < n)
        return;
    memcpy(p, body, n);
    p += n;
    lws_write(wsi, start, (size_t)(p - start), LWS_WRITE_HTTP_FINAL);
}

static enum ncp_http_stat stat_of(int status)
{
    return status == 403 ? NCP_HTTP_STAT_FOREIGN_ORIGIN
           : status == 421 ? NCP_HTTP_STAT_BAD_HOST : NCP_HTTP_STAT_BAD_REQUEST;
}

int ncp_http_on_gate(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                     size_t len)
{
    if (reason != LWS_CALLBACK_FILTER_HTTP_CONNECTION &&
        reason != LWS_CALLBACK_HTTP_CONFIRM_UPGRADE)
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    const struct ncp_http_floor *f = ncp_http_floor_of(wsi);
    char host[VALUE_MAX], origin[VALUE_MAX], cl[VALUE_MAX], te[VALUE_MAX];
    struct ncp_http_head hd;
    hd.n_host = header(wsi, WSI_TOKEN_HOST, host, sizeof host, &hd.host);
    hd.n_origin = header(wsi, WSI_TOKEN_ORIGIN, origin, sizeof origin, &hd.origin);
    hd.n_content_length =
        header(wsi, WSI_TOKEN_HTTP_CONTENT_LENGTH, cl, sizeof cl, &hd.content_length);
    hd.n_transfer_encoding =
        header(wsi, WSI_TOKEN_HTTP_TRANSFER_ENCODING, te, sizeof te, &hd.transfer_encoding);
    char why[300];
    int status = ncp_http_head_verdict(f->policy, &hd, why, sizeof why);
    if (!status)
        return 0;
    f->count(f->ctx, stat_of(status));
    refuse_http(wsi, status, why);
    /* an upgrade's refusal: -1 hangs up (libwebsockets would otherwise wait
     * for a next request on this connection); a request's: any non-zero */
    return -1;
}
