/* The build without libwebsockets: --http is refused with the reason. */
#include "ncpar/http.h"

#include <stddef.h>

int ncp_http_available(void)
{
    return 0;
}

struct ncp_http *ncp_http_start(const struct ncp_http_opts *o, struct ncp_diag *d)
{
    (void)o;
    ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                 "--http: this cnc-run was built without libwebsockets (install "
                 "libwebsockets-dev and rebuild)");
    return NULL;
}

void ncp_http_stop(struct ncp_http *h)
{
    (void)h;
}

const char *ncp_http_token(const struct ncp_http *h)
{
    (void)h;
    return "";
}

const struct ncp_nck_serve_hook *ncp_http_hook(struct ncp_http *h)
{
    (void)h;
    return NULL;
}

void ncp_http_get_stats(struct ncp_http *h, struct ncp_http_stats *st)
{
    (void)h;
    *st = (struct ncp_http_stats){ 0 };
}
