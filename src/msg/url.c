/* LCM's URL for UDP multicast, as liblcm reads it:
 *   udpm://GROUP:PORT?ttl=N&recv_buf_size=N
 * with its defaults (group 239.255.76.67, port 7667, ttl 0). */
#include <arpa/inet.h>
#include <errno.h>
#include <limits.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/msg.h"

#define DEFAULT_GROUP "239.255.76.67"
#define DEFAULT_PORT 7667

/* A whole decimal number in [lo, hi] from s[0..n). */
static int parse_num(const char *s, size_t n, long lo, long hi, long *out)
{
    char tmp[24];
    if (n == 0 || n >= sizeof tmp)
        return -1;
    memcpy(tmp, s, n);
    tmp[n] = 0;
    char *end;
    errno = 0;
    long v = strtol(tmp, &end, 10);
    if (errno != 0 || *end != 0 || tmp[0] == '-' || tmp[0] == '+' || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static int parse_option(const char *url, const char *opt, size_t n, struct ncp_msg_url *u,
                        struct ncp_diag *d)
{
    const char *eq = memchr(opt, '=', n);
    if (eq == NULL)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "LCM URL '%s': option '%.*s' has no value (NAME=VALUE)", url,
                            (int)n, opt);
    size_t klen = (size_t)(eq - opt);
    const char *val = eq + 1;
    size_t vlen = n - klen - 1;
    long v;
    if (klen == 3 && memcmp(opt, "ttl", 3) == 0) {
        if (parse_num(val, vlen, 0, 255, &v) != 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "LCM URL '%s': ttl must be a number from 0 to 255", url);
        u->ttl = (int)v;
    } else if (klen == 13 && memcmp(opt, "recv_buf_size", 13) == 0) {
        if (parse_num(val, vlen, 1, INT_MAX, &v) != 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "LCM URL '%s': recv_buf_size must be a number of bytes", url);
        u->recv_buf_size = (int)v;
    } else {
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "LCM URL '%s': unknown option '%.*s' (ttl and recv_buf_size are "
                            "understood)",
                            url, (int)klen, opt);
    }
    return NCP_OK;
}

int ncp_msg_parse_url(const char *url, struct ncp_msg_url *u, struct ncp_diag *d)
{
    static const char scheme[] = "udpm://";
    memset(u, 0, sizeof *u);
    memcpy(u->group, DEFAULT_GROUP, sizeof DEFAULT_GROUP);
    u->port = DEFAULT_PORT;
    if (strncmp(url, scheme, sizeof scheme - 1) != 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "LCM URL '%s': only udpm:// (UDP multicast) is understood, "
                            "e.g. udpm://239.255.76.67:7667?ttl=0",
                            url);
    const char *net = url + sizeof scheme - 1;
    const char *q = strchr(net, '?');
    size_t netlen = q ? (size_t)(q - net) : strlen(net);
    const char *colon = memchr(net, ':', netlen);
    size_t glen = colon ? (size_t)(colon - net) : netlen;
    if (glen > 0) {
        struct in_addr a;
        if (glen >= sizeof u->group)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "LCM URL '%s': '%.*s' is not a multicast group address "
                                "(224.0.0.0 to 239.255.255.255)",
                                url, (int)glen, net);
        memcpy(u->group, net, glen);
        u->group[glen] = 0;
        if (inet_pton(AF_INET, u->group, &a) != 1 || !IN_MULTICAST(ntohl(a.s_addr)))
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "LCM URL '%s': '%s' is not a multicast group address "
                                "(224.0.0.0 to 239.255.255.255)",
                                url, u->group);
    }
    if (colon) {
        long port;
        if (parse_num(colon + 1, netlen - glen - 1, 1, 65535, &port) != 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "LCM URL '%s': the port must be a number from 1 to 65535", url);
        u->port = (uint16_t)port;
    }
    for (const char *opt = q ? q + 1 : NULL; opt && *opt;) {
        const char *amp = strchr(opt, '&');
        size_t n = amp ? (size_t)(amp - opt) : strlen(opt);
        if (n > 0) {
            int rc = parse_option(url, opt, n, u, d);
            if (rc != NCP_OK)
                return rc;
        }
        opt = amp ? amp + 1 : NULL;
    }
    return NCP_OK;
}
