/* libFuzzer target for what the panel parses of a browser's or a client's
 * bytes: a request's head as the gate judges it (Origin, Host, framing:
 * policy.c, with the allow lists read from the same input), then one
 * WebSocket message as a command (request.c, flatjson.c) and an upload's
 * name. Input: the head's header lines up to a blank line, then the
 * message. Beyond "no crash, no hang, no leak", the verdicts must keep
 * their promises: a request let through has one Host, at most one
 * well-formed Content-Length, no Transfer-Encoding, and no Origin that is
 * null or not http(s); a refusal always says why. */
#include "ncpar/http.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define VALUE_MAX 512

struct field {
    const char *name;
    char value[VALUE_MAX];
    int n;
};

/* "Name: value" lines of the head (the first is the allow list, as an INI
 * line would give it); the message after the blank line. */
static size_t split_head(const char *in, size_t len, char *allow, struct field *f, int nf)
{
    size_t at = 0, line_no = 0;
    while (at < len) {
        const char *nl = memchr(in + at, '\n', len - at);
        size_t end = nl ? (size_t)(nl - in) : len, n = end - at;
        if (n && in[at + n - 1] == '\r')
            n--;
        const char *line = in + at;
        at = nl ? end + 1 : len;
        if (n == 0)
            break;
        if (line_no++ == 0) {
            size_t k = n < VALUE_MAX - 1 ? n : VALUE_MAX - 1;
            memcpy(allow, line, k);
            allow[k] = 0;
            continue;
        }
        const char *colon = memchr(line, ':', n);
        if (!colon)
            continue;
        size_t name_len = (size_t)(colon - line);
        for (int i = 0; i < nf; i++) {
            if (strlen(f[i].name) != name_len || strncasecmp(line, f[i].name, name_len))
                continue;
            const char *v = colon + 1;
            size_t vn = n - name_len - 1;
            while (vn && (*v == ' ' || *v == '\t'))
                v++, vn--;
            if (f[i].n++ == 0) {
                size_t k = vn < VALUE_MAX - 1 ? vn : VALUE_MAX - 1;
                memcpy(f[i].value, v, k);
                f[i].value[k] = 0;
            }
        }
    }
    return at;
}

static void judge(const char *allow, struct field *f)
{
    struct ncp_http_policy p;
    char why[300];
    /* the same list as origins and as hosts: most of it is refused, and
     * that path is exercised as much as the accepting one */
    if (ncp_http_policy_init(&p, "127.0.0.1", 8080, allow, allow, why, sizeof why)) {
        if (!why[0])
            abort();
        if (ncp_http_policy_init(&p, "::", 8080, NULL, NULL, why, sizeof why))
            abort();
    }
    struct ncp_http_head h = {
        .host = f[0].n ? f[0].value : NULL, .n_host = f[0].n,
        .origin = f[1].n ? f[1].value : NULL, .n_origin = f[1].n,
        .content_length = f[2].n ? f[2].value : NULL, .n_content_length = f[2].n,
        .transfer_encoding = f[3].n ? f[3].value : NULL, .n_transfer_encoding = f[3].n,
    };
    why[0] = 0;
    int v = ncp_http_head_verdict(&p, &h, why, sizeof why);
    if (v != 0 && v != 400 && v != 403 && v != 411 && v != 421)
        abort();
    if (v && (!why[0] || !memchr(why, 0, sizeof why)))
        abort();
    if (v)
        return;
    if (h.n_host != 1 || h.n_content_length > 1 || h.n_transfer_encoding)
        abort();
    if (h.n_content_length && strspn(h.content_length, "0123456789") != strlen(h.content_length))
        abort();
    if (h.n_origin && (h.n_origin != 1 || !strcasecmp(h.origin, "null") ||
                       (strncasecmp(h.origin, "http://", 7) && strncasecmp(h.origin, "https://", 8))))
        abort();
}

static void message(const char *msg, size_t len)
{
    ncp_command_t c;
    int unknown = 0;
    char why[128];
    why[0] = 0;
    enum ncp_http_req r = ncp_http_parse_request(msg, len, 0x57000001, &c, &unknown, why, sizeof why);
    if (r < NCP_HTTP_REQ_BAD || r > NCP_HTTP_REQ_PREVIEW)
        abort();
    if (r == NCP_HTTP_REQ_BAD && !why[0])
        abort();
    if (r == NCP_HTTP_REQ_COMMAND && c.client_id != 0x57000001)
        abort();
    char name[NCP_HTTP_UPLOAD_NAME_MAX + 8];
    size_t n = len < sizeof name - 1 ? len : sizeof name - 1;
    memcpy(name, msg, n);
    name[n] = 0;
    why[0] = 0;
    if (!ncp_http_upload_name_ok(name, why, sizeof why) && !why[0])
        abort();
    if (ncp_http_upload_name_ok(name, why, sizeof why) && (strchr(name, '/') || name[0] == '.'))
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *in = (const char *)data;
    char allow[VALUE_MAX] = "";
    struct field f[] = { { "Host", "", 0 }, { "Origin", "", 0 }, { "Content-Length", "", 0 },
                         { "Transfer-Encoding", "", 0 } };
    size_t body = split_head(in, size, allow, f, 4);
    judge(allow, f);
    message(in + body, size - body);
    return 0;
}
