/* The browser's command names and fields, mapped onto the LCM command type.
 * The filled command is encoded and decoded with the LCM path's own check
 * (ncp_msg_decode_command), so the browser can send nothing the LCM channel
 * would refuse. */
#include "flatjson.h"

#include "ncpar/http.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Where a field goes: text, value[i] or ivalue[i]. */
enum slot { TEXT, V0, V1, I0, I1, NONE };

struct field {
    const char *name;
    enum slot slot;
};

struct verb {
    const char *name;
    int kind;                   /* NCP_CMD_*, or -(enum ncp_http_req) for the panel's own */
    struct field fields[4];
};

/* SHUTDOWN is not offered: the panel never ends the service. */
static const struct verb verbs[] = {
    { "load", NCP_CMD_LOAD, { { "path", TEXT } } },
    { "run", NCP_CMD_RUN, { { "line", I0 } } },
    { "pause", NCP_CMD_PAUSE, { { 0, NONE } } },
    { "resume", NCP_CMD_RESUME, { { 0, NONE } } },
    { "stop", NCP_CMD_STOP, { { 0, NONE } } },
    { "abort", NCP_CMD_ABORT, { { 0, NONE } } },
    { "step", NCP_CMD_STEP, { { "on", I0 } } },
    { "mdi", NCP_CMD_MDI, { { "text", TEXT } } },
    { "jog", NCP_CMD_JOG, { { "axis", TEXT }, { "dir", I0 }, { "speed", V0 }, { "dist", V1 } } },
    { "jog_stop", NCP_CMD_JOG_STOP, { { "axis", TEXT } } },
    { "home", NCP_CMD_HOME, { { "axis", TEXT } } },
    { "override", NCP_CMD_OVERRIDE, { { "which", I0 }, { "value", V0 } } },
    { "estop", NCP_CMD_ESTOP, { { 0, NONE } } },
    { "reset", NCP_CMD_RESET, { { 0, NONE } } },
    { "keepalive", NCP_CMD_KEEPALIVE, { { 0, NONE } } },
    { "tool_changed", NCP_CMD_TOOL_CHANGED, { { 0, NONE } } },
    { "optional_stop", NCP_CMD_OPTIONAL_STOP, { { "on", I0 } } },
    { "set_input", NCP_CMD_SET_INPUT, { { "input", I0 }, { "on", I1 } } },
    { "list", -NCP_HTTP_REQ_LIST, { { 0, NONE } } },
    { "program", -NCP_HTTP_REQ_PROGRAM, { { 0, NONE } } },
    { "preview", -NCP_HTTP_REQ_PREVIEW, { { 0, NONE } } },
    { "tools", -NCP_HTTP_REQ_TOOLS, { { 0, NONE } } },
    { "history", -NCP_HTTP_REQ_HISTORY, { { 0, NONE } } },
    { "got", -NCP_HTTP_REQ_GOT, { { "id", I0 }, { "parts", I1 } } },
};

static const struct field *field_of(const struct verb *v, const char *key)
{
    for (int i = 0; i < 4 && v->fields[i].name; i++)
        if (!strcmp(v->fields[i].name, key))
            return &v->fields[i];
    return NULL;
}

/* "feed", "rapid", "spindle" as override's which (or its number). */
static int which_override(const struct ncp_fj_field *f, double *out)
{
    static const char *const names[] = { "feed", "rapid", "spindle" };
    if (f->type == NCP_FJ_NUMBER) {
        *out = f->num;
        return 0;
    }
    for (int i = 0; i < 3; i++)
        if (f->type == NCP_FJ_STRING && !strcmp(f->str, names[i]))
            return *out = i, 0;
    return -1;
}

static int put_field(ncp_command_t *c, const struct field *fd, const struct ncp_fj_field *f,
                     char *why, size_t wl)
{
    double num = f->num;
    if (fd->slot == TEXT) {
        if (f->type != NCP_FJ_STRING)
            return snprintf(why, wl, "\"%s\" must be a string", fd->name), -1;
        snprintf((char *)c->text, sizeof c->text, "%s", f->str);
        return 0;
    }
    if (c->kind == NCP_CMD_OVERRIDE && fd->slot == I0) {
        if (which_override(f, &num))
            return snprintf(why, wl, "\"which\" is feed, rapid or spindle"), -1;
    } else if (f->type != NCP_FJ_NUMBER && f->type != NCP_FJ_BOOL) {
        return snprintf(why, wl, "\"%s\" must be a number", fd->name), -1;
    }
    if (fd->slot == I0 || fd->slot == I1) {
        if (num != floor(num) || fabs(num) > 2147483647.0)
            return snprintf(why, wl, "\"%s\" must be an integer", fd->name), -1;
        c->ivalue[fd->slot == I0 ? 0 : 1] = (int32_t)num;
    } else {
        c->value[fd->slot == V0 ? 0 : 1] = num;
    }
    return 0;
}

/* The message's fields but "cmd" into c: the verb's own, and "seq" where
 * takes_seq (a got has none). 0, or -1 with why said. */
static int put_fields(const struct verb *v, const struct ncp_fj *o, int takes_seq,
                      ncp_command_t *c, char *why, size_t wl)
{
    for (int i = 0; i < o->n; i++) {
        const struct ncp_fj_field *f = &o->f[i];
        if (!strcmp(f->key, "cmd"))
            continue;
        if (takes_seq && !strcmp(f->key, "seq")) {
            if (f->type != NCP_FJ_NUMBER || f->num != floor(f->num) || f->num < 1 ||
                f->num > 2147483647.0)
                return snprintf(why, wl, "\"seq\" must be an integer from 1"), -1;
            c->seq = (int32_t)f->num;
            continue;
        }
        const struct field *fd = field_of(v, f->key);
        if (!fd)
            return snprintf(why, wl, "%s takes no \"%s\"", v->name, f->key), -1;
        if (put_field(c, fd, f, why, wl))
            return -1;
    }
    return 0;
}

/* {"cmd": "got", "id": ID, "parts": N}: both, positive integers, nothing else. */
static enum ncp_http_req parse_got(const struct verb *v, const struct ncp_fj *o,
                                   ncp_command_t *c, char *why, size_t wl)
{
    if (put_fields(v, o, 0, c, why, wl))
        return NCP_HTTP_REQ_BAD;
    if (c->ivalue[0] < 1 || c->ivalue[1] < 1)
        return snprintf(why, wl, "got needs \"id\" and \"parts\" from 1"), NCP_HTTP_REQ_BAD;
    return NCP_HTTP_REQ_GOT;
}

enum ncp_http_req ncp_http_parse_request(const char *json, size_t len, int32_t client_id,
                                         ncp_command_t *c, int *unknown, char *why,
                                         size_t wl)
{
    static struct ncp_fj o;   /* 8 text fields: too big for the server's stack habits */
    *unknown = 0;
    if (ncp_fj_parse(json, len, &o))
        return snprintf(why, wl, "not a flat JSON object"), NCP_HTTP_REQ_BAD;
    const struct ncp_fj_field *name = ncp_fj_get(&o, "cmd");
    if (!name || name->type != NCP_FJ_STRING)
        return snprintf(why, wl, "no \"cmd\""), NCP_HTTP_REQ_BAD;
    const struct verb *v = NULL;
    for (size_t i = 0; i < sizeof verbs / sizeof verbs[0]; i++)
        if (!strcmp(verbs[i].name, name->str))
            v = &verbs[i];
    if (!v) {
        *unknown = 1;
        return snprintf(why, wl, "unknown command \"%.40s\"", name->str), NCP_HTTP_REQ_BAD;
    }
    if (v->kind < 0 && v->kind != -NCP_HTTP_REQ_GOT)
        return (enum ncp_http_req)-v->kind;
    memset(c, 0, sizeof *c);
    if (v->kind == -NCP_HTTP_REQ_GOT)
        return parse_got(v, &o, c, why, wl);
    c->kind = (int16_t)v->kind;
    c->client_id = client_id;
    if (v->kind == NCP_CMD_HOME)
        snprintf((char *)c->text, sizeof c->text, "all");
    if (put_fields(v, &o, 1, c, why, wl))
        return NCP_HTTP_REQ_BAD;
    if (c->seq == 0 && v->kind != NCP_CMD_KEEPALIVE)
        return snprintf(why, wl, "no \"seq\""), NCP_HTTP_REQ_BAD;
    /* the LCM path's own validation, on the bytes it would have received */
    static uint8_t wire[1024];
    int n = ncp_command_t_encode(wire, 0, (int)sizeof wire, c);
    ncp_command_t back;
    if (n <= 0 || ncp_msg_decode_command(wire, (size_t)n, &back))
        return snprintf(why, wl, "not a valid command"), NCP_HTTP_REQ_BAD;
    *c = back;
    return NCP_HTTP_REQ_COMMAND;
}

int ncp_http_json_string(char *buf, size_t size, size_t *len, const char *s, size_t n)
{
    static const char hex[] = "0123456789abcdef";
    size_t k = *len;
    if (k + 2 > size)
        return -1;
    buf[k++] = '"';
    for (size_t i = 0; i < n; i++) {
        unsigned char ch = (unsigned char)s[i];
        if (k + 7 > size) {
            *len = k;
            return -1;
        }
        if (ch == '"' || ch == '\\') {
            buf[k++] = '\\';
            buf[k++] = (char)ch;
        } else if (ch == '\n') {
            buf[k++] = '\\';
            buf[k++] = 'n';
        } else if (ch < 0x20 || ch == 0x7f) {
            memcpy(buf + k, "\\u00", 4);
            buf[k + 4] = hex[ch >> 4];
            buf[k + 5] = hex[ch & 15];
            k += 6;
        } else {
            buf[k++] = (char)ch;
        }
    }
    if (k + 2 > size) {
        *len = k;
        return -1;
    }
    buf[k++] = '"';
    buf[k] = 0;
    *len = k;
    return 0;
}
