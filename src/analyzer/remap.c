/* REMAP lines read as rs274 -i reads them (its parse_remap): the code, then
 * options kw=value. ncpar runs M and G codes, T, S and F remapped to ngc=
 * subroutines, with stdglue.py's tool, speed and feed prologs and epilogs
 * built in; what needs LinuxCNC's Python plugin otherwise (python=, other
 * prologs) is refused here, naming the INI line, so that nothing of the
 * configuration is silently dropped. */
#include "remap.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

static int remap_error(struct ncp_diag *d, const struct ncp_remap_line *l, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int remap_error(struct ncp_diag *d, const struct ncp_remap_line *l, const char *fmt, ...)
{
    char msg[NCP_DIAG_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int rc = ncp_diag_set(d, NCP_ERR_SEMANTIC, l->line, 0, "REMAP: %s", msg);
    d->file = l->file ? ncp_diag_file_of_tag(ncp_diag_file_tag(l->file)) : NULL;
    return rc;
}

/* rs274 2.9's M_REMAPPABLE: codes with no meaning of their own, and the
 * listed ones whose built-in step a remap may take over (M7 and M8 are not:
 * a REMAP of them leaves the built-in code, as rs274 -i 2.9 shows). */
static int remappable_m(int m)
{
    switch (m) {
    case 0: case 1: case 6: case 9: case 60: case 61: case 62: case 63:
    case 64: case 65: case 66: case 67: case 68:
        return 1;
    case 2: case 3: case 4: case 5: case 7: case 8: case 19: case 30: case 48: case 49:
    case 50: case 51: case 52: case 53: case 70: case 71: case 72: case 73: case 98: case 99:
        return 0;
    default:
        return (m > 0 && m < 100) || (m > 199 && m < NCP_REMAP_M_MAX);
    }
}

/* Like rs274: NAME.ngc in the current folder or a subroutine path folder. */
static int ngc_found(const char *sub_path, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s.ngc", name);
    if (access(path, R_OK) == 0)
        return 1;
    const char *p = sub_path;
    while (p && *p) {
        const char *end = strchr(p, ':');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (n > 0 && n < sizeof path - 8 - strlen(name)) {
            snprintf(path, sizeof path, "%.*s/%s.ngc", (int)n, p, name);
            if (access(path, R_OK) == 0)
                return 1;
        }
        p = end ? end + 1 : NULL;
    }
    return 0;
}

static int glue_of(const char *name, int epilog, enum ncp_glue *out)
{
    if (!strcmp(name, epilog ? "prepare_epilog" : "prepare_prolog"))
        *out = NCP_GLUE_PREPARE;
    else if (!strcmp(name, epilog ? "change_epilog" : "change_prolog"))
        *out = NCP_GLUE_CHANGE;
    else if (!strcmp(name, epilog ? "settool_epilog" : "settool_prolog"))
        *out = NCP_GLUE_SETTOOL;
    else if (!strcmp(name, epilog ? "setspeed_epilog" : "setspeed_prolog"))
        *out = NCP_GLUE_SETSPEED;
    else if (!strcmp(name, epilog ? "setfeed_epilog" : "setfeed_prolog"))
        *out = NCP_GLUE_SETFEED;
    else
        return -1;
    return 0;
}

/* G88.1 is code 881, G88 880, as rs274 numbers them (its "%d.%d", then "%d"
 * times ten). Only modal group 1 (the motion's, its default) is rs274's; a
 * code of its own (G88.1) runs the sub, one rs274 has (G1, G17) only moves
 * to group 1 and runs built in, as there. */
static int remap_parse_g(const struct ncp_remap_line *l, struct ncp_remap *r,
                         struct ncp_diag *d)
{
    int g1 = 0, g2 = 0, code = -1;
    if (sscanf(r->code + 1, "%d.%d", &g1, &g2) == 2)
        code = g1 * 10 + g2;
    else if (sscanf(r->code + 1, "%d", &g1) == 1)
        code = g1 * 10;
    else
        return remap_error(d, l, "code '%s' : can't parse G-code", r->code);
    if (code < 0 || code >= NCP_REMAP_G_MAX)
        return remap_error(d, l, "code '%s' : G-code out of range (G0 .. G99.9)", r->code);
    r->m = -1;
    r->g = code;
    if (r->group == -1)
        r->group = 1; /* rs274's default, with a warning */
    if (r->group != 1)
        return remap_error(d, l, "code '%s' : invalid modalgroup=<int> given (currently "
                           "valid: 1)", r->code);
    r->remappable = 1; /* until words.c finds it is one of rs274's own */
    return NCP_OK;
}

static int remap_parse(const struct ncp_remap_line *l, const char *sub_path,
                       struct ncp_remap *r, struct ncp_diag *d)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", l->text ? l->text : "");
    char *hash = strchr(buf, '#'); /* rs274 strips a trailing comment */
    if (hash)
        *hash = '\0';
    char *save = NULL;
    char *code = strtok_r(buf, " \t", &save);
    if (!code)
        return remap_error(d, l, "no code to remap");
    memset(r, 0, sizeof *r);
    r->group = -1;
    if (strlen(code) >= sizeof r->code)
        return remap_error(d, l, "code '%.20s...' is too long", code);
    snprintf(r->code, sizeof r->code, "%s", code);
    int has_ngc = 0;
    for (char *kw = strtok_r(NULL, " \t", &save); kw; kw = strtok_r(NULL, " \t", &save)) {
        char *arg = strchr(kw, '=');
        if (!arg)
            return remap_error(d, l, "option '%s' - missing '=<value>'", kw);
        size_t kwlen = (size_t)(arg - kw);
        arg++;
        if (!*arg)
            return remap_error(d, l, "option '%s' - zero length value", kw);
        if (!strncasecmp(kw, "modalgroup", kwlen)) {
            r->group = atoi(arg);
        } else if (!strncasecmp(kw, "argspec", kwlen)) {
            size_t pos = strspn(arg, "ABCDEFGHIJKLMNPQRSTUVWXYZabcdefghijklmnpqrstuvwxyz>^@");
            if (arg[pos])
                return remap_error(d, l, "argspec: illegal word '%c'", arg[pos]);
            if (strchr(arg, 'N') || strchr(arg, 'n'))
                return remap_error(d, l, "argspec: N (the line number) is not supported by ncpar");
            if (strlen(arg) >= sizeof r->argspec)
                return remap_error(d, l, "argspec: longer than %zu characters",
                                   sizeof r->argspec - 1);
            snprintf(r->argspec, sizeof r->argspec, "%s", arg);
        } else if (!strncasecmp(kw, "ngc", kwlen)) {
            if (strlen(arg) >= sizeof r->ngc)
                return remap_error(d, l, "ngc=%.20s...: name longer than %zu characters", arg,
                                   sizeof r->ngc - 1);
            if (!ngc_found(sub_path, arg))
                return remap_error(d, l, "NGC file not found: ngc=%s", arg);
            snprintf(r->ngc, sizeof r->ngc, "%s", arg);
            has_ngc = 1;
        } else if ((!strncasecmp(kw, "prolog", kwlen) && !glue_of(arg, 0, &r->prolog)) ||
                   (!strncasecmp(kw, "epilog", kwlen) && !glue_of(arg, 1, &r->epilog))) {
            /* stdglue's, built in */
        } else if (!strncasecmp(kw, "python", kwlen) || !strncasecmp(kw, "prolog", kwlen) ||
                   !strncasecmp(kw, "epilog", kwlen)) {
            return remap_error(d, l, "%.*s=%s needs LinuxCNC's Python plugin, which ncpar does "
                               "not have (its built-in stdglue prologs and epilogs: "
                               "prepare_*, change_*, settool_*, setspeed_*, setfeed_*)", (int)kwlen, kw, arg);
        } else {
            return remap_error(d, l, "unrecognized option '%.*s'", (int)kwlen, kw);
        }
    }
    if (!has_ngc)
        return remap_error(d, l, "code '%s' - no remap function given, use 'ngc=<basename>'",
                           r->code);
    int letter = toupper((unsigned char)code[0]);
    if (letter == 'T' || letter == 'S' || letter == 'F') {
        if (code[1])
            return remap_error(d, l, "%s remap - only single letter code allowed", r->code);
        if (r->group != -1)
            return remap_error(d, l, "%c remap - modal group setting ignored - fixed sequencing",
                               letter);
        r->m = r->g = -1;
        r->remappable = 1;
        return NCP_OK;
    }
    if (letter == 'G')
        return remap_parse_g(l, r, d);
    r->g = -1;
    if (letter != 'M')
        return remap_error(d, l, "code '%s': ncpar remaps M and G codes, T, S and F only",
                           r->code);
    char *end = NULL;
    long m = strtol(code + 1, &end, 10);
    if (end == code + 1 || *end || m < 0 || m >= NCP_REMAP_M_MAX)
        return remap_error(d, l, "parsing M-code: expecting integer like 'M420', got '%s'",
                           r->code);
    r->m = (int)m;
    if (r->group == -1)
        r->group = 10; /* rs274's default, with a warning */
    if (r->group < 4 || r->group > 10)
        return remap_error(d, l, "code '%s' : invalid modalgroup=<int> given (currently "
                           "valid: 4..10)", r->code);
    r->remappable = remappable_m(r->m);
    return NCP_OK;
}

int ncp_remaps_new(const struct ncp_analyzer_cfg *cfg, struct ncp_remaps **out,
                   struct ncp_diag *d)
{
    *out = NULL;
    if (!cfg || cfg->n_remaps <= 0)
        return NCP_OK;
    struct ncp_remaps *rs = calloc(1, sizeof *rs);
    if (rs)
        rs->r = calloc((size_t)cfg->n_remaps, sizeof *rs->r);
    if (!rs || !rs->r) {
        ncp_remaps_free(rs);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
    }
    memset(rs->by_m, 0xff, sizeof rs->by_m);
    memset(rs->by_g, 0xff, sizeof rs->by_g);
    rs->t = rs->s = rs->f = -1;
    for (int k = 0; k < cfg->n_remaps; k++) {
        struct ncp_remap *r = &rs->r[rs->n];
        int rc = remap_parse(&cfg->remaps[k], cfg->subroutine_path, r, d);
        int *letter = NULL; /* T's, S's or F's slot */
        int16_t *slot = NULL; /* an M or G code's */
        if (rc == NCP_OK && r->m >= 0)
            slot = &rs->by_m[r->m];
        else if (rc == NCP_OK && r->g >= 0)
            slot = &rs->by_g[r->g];
        else if (rc == NCP_OK)
            letter = toupper((unsigned char)r->code[0]) == 'T'   ? &rs->t
                     : toupper((unsigned char)r->code[0]) == 'S' ? &rs->s
                                                                 : &rs->f;
        if (rc == NCP_OK && (letter ? *letter : *slot) >= 0)
            rc = remap_error(d, &cfg->remaps[k], "code '%s' already remapped", r->code);
        if (rc != NCP_OK) {
            ncp_remaps_free(rs);
            return rc;
        }
        if (letter)
            *letter = rs->n++;
        else
            *slot = (int16_t)rs->n++;
        rs->n_g += r->g >= 0;
    }
    *out = rs;
    return NCP_OK;
}

void ncp_remaps_free(struct ncp_remaps *rs)
{
    if (!rs)
        return;
    free(rs->r);
    free(rs);
}
