/* Who may talk to the panel at all: Origin, Host and the request's framing,
 * judged before the token and before libwebsockets serves anything.
 *
 * A browser attaches Origin to every WebSocket upgrade and every POST, and
 * a page cannot forge it: a page from elsewhere (or a sandboxed one, "null")
 * is refused whether it knows the token or not. A DNS-rebinding page is of
 * the panel's own origin as the browser sees it (its name now resolves to
 * the panel), so Origin alone cannot stop it; its Host is still the
 * attacker's name, which is not one the panel answers to (421). Tools
 * without a browser send no Origin and are judged by the token.
 *
 * Framing: libwebsockets reads a body by its Content-Length and knows no
 * chunked request bodies, so a request whose length two parties could read
 * differently (two lengths, a length and a transfer coding) is refused, and
 * a chunked one asked for its length. Pure functions: the fuzz target and
 * the unit test call them as the server does. */
#include "ncpar/http.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* A host name, an IPv4 address or a bracketed IPv6 one, with an optional
 * port: "name[:port]". 0, or -1 when it is none of these. */
static int parse_hostport(const char *s, size_t n, struct ncp_http_origin *o)
{
    size_t i = 0, k = 0;
    if (n && s[0] == '[') {
        const char *close = memchr(s, ']', n);
        if (!close || close == s + 1)
            return -1;
        for (i = 1; s + i < close; i++)
            if (!isxdigit((unsigned char)s[i]) && s[i] != ':' && s[i] != '.')
                return -1;
        i++;   /* past ']' */
    } else {
        while (i < n && (isalnum((unsigned char)s[i]) || s[i] == '-' || s[i] == '.' ||
                         s[i] == '_'))
            i++;
        if (i == 0)
            return -1;
    }
    if (i >= sizeof o->host)
        return -1;
    for (k = 0; k < i; k++)
        o->host[k] = (char)tolower((unsigned char)s[k]);
    o->host[i] = 0;
    o->port = 0;
    if (i == n)
        return 0;
    if (s[i] != ':' || i + 1 == n || n - i - 1 > 5)
        return -1;
    int port = 0;
    for (k = i + 1; k < n; k++) {
        if (!isdigit((unsigned char)s[k]))
            return -1;
        port = port * 10 + (s[k] - '0');
    }
    if (port < 1 || port > 65535)
        return -1;
    o->port = port;
    return 0;
}

/* "http[s]://host[:port]", nothing after: what a browser sends as Origin. */
static int parse_origin(const char *s, size_t n, struct ncp_http_origin *o)
{
    size_t skip;
    if (n > 7 && !strncasecmp(s, "http://", 7)) {
        o->https = 0;
        skip = 7;
    } else if (n > 8 && !strncasecmp(s, "https://", 8)) {
        o->https = 1;
        skip = 8;
    } else {
        return -1;
    }
    return parse_hostport(s + skip, n - skip, o);
}

static int effective_port(const struct ncp_http_origin *o)
{
    return o->port ? o->port : o->https ? 443 : 80;
}

static int same_origin(const struct ncp_http_origin *a, const struct ncp_http_origin *b)
{
    return a->https == b->https && !strcmp(a->host, b->host) &&
           effective_port(a) == effective_port(b);
}

/* The next entry of a space- or comma-separated list: its start and length,
 * 0 at the end. */
static size_t next_entry(const char **list, const char **start)
{
    const char *p = *list + strspn(*list, " \t,");
    size_t n = strcspn(p, " \t,");
    *start = p;
    *list = p + n;
    return n;
}

static int parse_entry(const char *e, size_t n, int origins, struct ncp_http_origin *o,
                       char *why, size_t wl)
{
    if (origins && n == 4 && !strncasecmp(e, "null", 4))
        return snprintf(why, wl, "'null' is the origin of sandboxed and local pages: "
                                 "never allowed"), -1;
    int bad = origins ? parse_origin(e, n, o) : parse_hostport(e, n, o);
    if (bad)
        return snprintf(why, wl, origins ? "'%.*s' is no origin (http://HOST[:PORT] or "
                                           "https://HOST[:PORT], no path)"
                                         : "'%.*s' is no host (NAME[:PORT], ADDRESS[:PORT] "
                                           "or [IPv6][:PORT])",
                        (int)(n > 40 ? 40 : n), e), -1;
    return 0;
}

static int parse_list(const char *list, int origins, struct ncp_http_origin *out, int *count,
                      char *why, size_t wl)
{
    *count = 0;
    const char *e;
    size_t n;
    while (list && (n = next_entry(&list, &e)) > 0) {
        if (*count == NCP_HTTP_ALLOW_MAX)
            return snprintf(why, wl, "at most %d entries", NCP_HTTP_ALLOW_MAX), -1;
        if (parse_entry(e, n, origins, &out[*count], why, wl))
            return -1;
        if (!origins)
            out[*count].https = 0;
        (*count)++;
    }
    return 0;
}

int ncp_http_allow_list_ok(const char *list, int origins, char *why, size_t wl)
{
    struct ncp_http_origin entries[NCP_HTTP_ALLOW_MAX];
    int n;
    return parse_list(list, origins, entries, &n, why, wl);
}

int ncp_http_policy_init(struct ncp_http_policy *p, const char *addr, int port,
                         const char *allow_origin, const char *allow_host, char *why, size_t wl)
{
    memset(p, 0, sizeof *p);
    p->port = port;
    /* a wildcard names no host: the machine's own addresses go in ALLOW_HOST */
    if (strcmp(addr, "0.0.0.0") != 0 && strcmp(addr, "::") != 0) {
        const char *fmt = strchr(addr, ':') ? "[%s]" : "%s";
        snprintf(p->addr, sizeof p->addr, fmt, addr);
        for (char *c = p->addr; *c; c++)
            *c = (char)tolower((unsigned char)*c);
    }
    char sub[200];
    if (parse_list(allow_origin, 1, p->allow_origin, &p->n_allow_origin, sub, sizeof sub))
        return snprintf(why, wl, "ALLOW_ORIGIN: %s", sub), -1;
    if (parse_list(allow_host, 0, p->allow_host, &p->n_allow_host, sub, sizeof sub))
        return snprintf(why, wl, "ALLOW_HOST: %s", sub), -1;
    return 0;
}

static int host_ok(const struct ncp_http_policy *p, const struct ncp_http_origin *h)
{
    static const char *const loopback[] = { "localhost", "127.0.0.1", "[::1]" };
    int port_ok = h->port == 0 || h->port == p->port;
    for (size_t i = 0; i < sizeof loopback / sizeof loopback[0]; i++)
        if (!strcmp(h->host, loopback[i]))
            return port_ok;
    if (p->addr[0] && !strcmp(h->host, p->addr))
        return port_ok;
    for (int i = 0; i < p->n_allow_host; i++) {
        const struct ncp_http_origin *a = &p->allow_host[i];
        if (!strcmp(h->host, a->host) && (a->port ? h->port == a->port : port_ok))
            return 1;
    }
    return 0;
}

static int digits_only(const char *s)
{
    size_t n = strlen(s);
    return n > 0 && n <= 18 && strspn(s, "0123456789") == n;
}

int ncp_http_head_verdict(const struct ncp_http_policy *p, const struct ncp_http_head *h,
                          char *why, size_t wl)
{
    struct ncp_http_origin host = { 0 };
    int host_parsed = h->n_host == 1 && h->host &&
                      parse_hostport(h->host, strlen(h->host), &host) == 0;
    if (h->n_origin) {
        struct ncp_http_origin o;
        int own = 0, allowed = 0;
        if (h->n_origin == 1 && h->origin && parse_origin(h->origin, strlen(h->origin), &o) == 0) {
            own = host_parsed && same_origin(&o, &host);
            for (int i = 0; i < p->n_allow_origin && !allowed; i++)
                allowed = same_origin(&o, &p->allow_origin[i]);
        }
        if (!own && !allowed)
            return snprintf(why, wl, "a page from elsewhere (Origin %.80s) may not use the "
                                     "panel; allow its origin in the machine INI's [HTTP] "
                                     "ALLOW_ORIGIN if it should",
                            h->n_origin == 1 && h->origin ? h->origin : "given twice"), 403;
    }
    if (h->n_host > 1)
        return snprintf(why, wl, "two Host headers"), 400;
    if (!h->n_host || !h->host)
        return snprintf(why, wl, "no Host header"), 400;
    if (!host_parsed || !host_ok(p, &host))
        return snprintf(why, wl, "this panel does not answer to the name '%.80s'; add it to "
                                 "the machine INI's [HTTP] ALLOW_HOST if it should", h->host),
               421;
    if (h->n_content_length > 1)
        return snprintf(why, wl, "two Content-Length headers"), 400;
    if (h->n_content_length && (!h->content_length || !digits_only(h->content_length)))
        return snprintf(why, wl, "Content-Length is no length"), 400;
    if (h->n_transfer_encoding && h->n_content_length)
        return snprintf(why, wl, "Content-Length and Transfer-Encoding together"), 400;
    if (h->n_transfer_encoding)
        return snprintf(why, wl, "send the body with a Content-Length: a chunked (or otherwise "
                                 "transfer-coded) body is not taken"), 411;
    return 0;
}
