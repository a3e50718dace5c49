/* --http's argument: [ADDR:]PORT. Only a numeric address: a name would need
 * a resolver at start and says less clearly which interface is exposed. */
#include "ncpar/http.h"
#include "ncpar/num.h"

#include <arpa/inet.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ncp_http_parse_listen(const char *spec, struct ncp_http_opts *o, struct ncp_diag *d)
{
    char host[64] = "127.0.0.1";
    const char *port = spec;
    const char *colon = strrchr(spec, ':');
    if (colon) {
        size_t n = (size_t)(colon - spec);
        const char *h = spec;
        if (n >= 2 && h[0] == '[' && h[n - 1] == ']') {
            h++;
            n -= 2;
        }
        if (n == 0 || n >= sizeof host) {
            ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: bad address in '%s'", spec);
            return -1;
        }
        memcpy(host, h, n);
        host[n] = 0;
        port = colon + 1;
    }
    unsigned char bin[16];
    if (inet_pton(AF_INET, host, bin) != 1 && inet_pton(AF_INET6, host, bin) != 1) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "--http: '%s' is no numeric IPv4 or [IPv6] address", host);
        return -1;
    }
    if (ncp_num_int(port, 1, 65535, &o->port)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "--http: '%s' is no port (1-65535)", port);
        return -1;
    }
    snprintf(o->addr, sizeof o->addr, "%s", host);
    return 0;
}
