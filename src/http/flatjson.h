/* A flat JSON object reader (src/http's private helper). */
#ifndef NCP_HTTP_FLATJSON_H
#define NCP_HTTP_FLATJSON_H

#include <stddef.h>

#include "ncpar/nck.h"

#define NCP_FJ_FIELDS 8

enum ncp_fj_type { NCP_FJ_STRING, NCP_FJ_NUMBER, NCP_FJ_BOOL, NCP_FJ_NULL };

struct ncp_fj_field {
    char key[16];
    enum ncp_fj_type type;
    double num;                     /* number, or 1/0 for a boolean */
    char str[NCP_NCK_TEXT_MAX];
};

struct ncp_fj {
    int n;
    struct ncp_fj_field f[NCP_FJ_FIELDS];
};

/* 0, or -1 when json is not one flat object of at most NCP_FJ_FIELDS
 * distinct keys whose strings fit their fields. */
int ncp_fj_parse(const char *json, size_t len, struct ncp_fj *o);
const struct ncp_fj_field *ncp_fj_get(const struct ncp_fj *o, const char *key);

#endif
