/* The browser's messages are flat JSON objects of strings, numbers, booleans
 * and null: this reads exactly that (strictly, nesting refused) into a small
 * fixed table, so a hostile message costs a bounded scan and no allocation. */
#include "flatjson.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct rd {
    const char *p, *end;
};

static void skip_ws(struct rd *r)
{
    while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\n' || *r->p == '\r'))
        r->p++;
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* Appends code point u as UTF-8; 0 when it does not fit. */
static int put_utf8(char *out, size_t size, size_t *n, unsigned u)
{
    char b[4];
    size_t k;
    if (u < 0x80) {
        b[0] = (char)u;
        k = 1;
    } else if (u < 0x800) {
        b[0] = (char)(0xc0 | (u >> 6));
        b[1] = (char)(0x80 | (u & 0x3f));
        k = 2;
    } else {
        b[0] = (char)(0xe0 | (u >> 12));
        b[1] = (char)(0x80 | ((u >> 6) & 0x3f));
        b[2] = (char)(0x80 | (u & 0x3f));
        k = 3;
    }
    if (*n + k >= size)
        return 0;
    memcpy(out + *n, b, k);
    *n += k;
    return 1;
}

/* A string at r->p (after its quote) into out (NUL-terminated). A NUL
 * character (\u0000) is refused: the command's text fields end at one. */
static int read_string(struct rd *r, char *out, size_t size)
{
    size_t n = 0;
    while (r->p < r->end) {
        char c = *r->p++;
        if (c == '"') {
            out[n] = 0;
            return 0;
        }
        if ((unsigned char)c < 0x20)
            return -1;
        if (c != '\\') {
            if (n + 1 >= size)
                return -1;
            out[n++] = c;
            continue;
        }
        if (r->p >= r->end)
            return -1;
        c = *r->p++;
        const char *simple = "\"\\/bfnrt", *value = "\"\\/\b\f\n\r\t";
        const char *k = strchr(simple, c);
        if (c && k) {
            if (n + 1 >= size)
                return -1;
            out[n++] = value[k - simple];
        } else if (c == 'u') {
            if (r->end - r->p < 4)
                return -1;
            unsigned u = 0;
            for (int i = 0; i < 4; i++) {
                int h = hexval(*r->p++);
                if (h < 0)
                    return -1;
                u = u << 4 | (unsigned)h;
            }
            /* surrogates: no G-code or path needs them */
            if (u == 0 || (u >= 0xd800 && u <= 0xdfff) || !put_utf8(out, size, &n, u))
                return -1;
        } else {
            return -1;
        }
    }
    return -1;
}

static int read_number(struct rd *r, double *v)
{
    char tmp[64];
    size_t n = 0;
    while (r->p < r->end && n + 1 < sizeof tmp && strchr("+-0123456789.eE", *r->p) && *r->p)
        tmp[n++] = *r->p++;
    tmp[n] = 0;
    if (n == 0 || (r->p < r->end && strchr("+-0123456789.eE", *r->p) && *r->p))
        return -1;
    char *end;
    errno = 0;
    *v = strtod(tmp, &end);
    return *end == 0 && errno == 0 && isfinite(*v) ? 0 : -1;
}

static int literal(struct rd *r, const char *word)
{
    size_t n = strlen(word);
    if ((size_t)(r->end - r->p) < n || memcmp(r->p, word, n) != 0)
        return -1;
    r->p += n;
    return 0;
}

static int read_value(struct rd *r, struct ncp_fj_field *f)
{
    if (r->p >= r->end)
        return -1;
    char c = *r->p;
    if (c == '"') {
        r->p++;
        f->type = NCP_FJ_STRING;
        return read_string(r, f->str, sizeof f->str);
    }
    if (c == 't' || c == 'f') {
        f->type = NCP_FJ_BOOL;
        f->num = c == 't';
        return literal(r, c == 't' ? "true" : "false");
    }
    if (c == 'n') {
        f->type = NCP_FJ_NULL;
        return literal(r, "null");
    }
    f->type = NCP_FJ_NUMBER;
    return read_number(r, &f->num);
}

int ncp_fj_parse(const char *json, size_t len, struct ncp_fj *o)
{
    struct rd r = { json, json + len };
    o->n = 0;
    skip_ws(&r);
    if (r.p >= r.end || *r.p++ != '{')
        return -1;
    skip_ws(&r);
    if (r.p < r.end && *r.p == '}') {
        r.p++;
    } else {
        for (;;) {
            if (o->n >= NCP_FJ_FIELDS)
                return -1;
            struct ncp_fj_field *f = &o->f[o->n];
            skip_ws(&r);
            if (r.p >= r.end || *r.p++ != '"' || read_string(&r, f->key, sizeof f->key))
                return -1;
            for (int i = 0; i < o->n; i++)
                if (!strcmp(o->f[i].key, f->key))
                    return -1;   /* a repeated key is ambiguous */
            skip_ws(&r);
            if (r.p >= r.end || *r.p++ != ':')
                return -1;
            skip_ws(&r);
            if (read_value(&r, f))
                return -1;
            o->n++;
            skip_ws(&r);
            if (r.p >= r.end)
                return -1;
            if (*r.p == ',') {
                r.p++;
                continue;
            }
            if (*r.p++ != '}')
                return -1;
            break;
        }
    }
    skip_ws(&r);
    return r.p == r.end ? 0 : -1;
}

const struct ncp_fj_field *ncp_fj_get(const struct ncp_fj *o, const char *key)
{
    for (int i = 0; i < o->n; i++)
        if (!strcmp(o->f[i].key, key))
            return &o->f[i];
    return NULL;
}
