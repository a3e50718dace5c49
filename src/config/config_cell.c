/* The channels INI of cnc-run serve ([CHANNEL_n] CONFIG, BACKEND, DP).
 * Read in the library beside the machine INI's reader so that its keys are
 * rows of ini_keys.c that tools/ini-man probes through this reader, and so
 * that the unit tests reach it. Every line it refuses is named: what the
 * backends make of the channels together is src/backend/cell.c's. */
#include "ncpar/config.h"
#include "ini_num.h"

#include <ini.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

struct cell_read {
    struct ncp_cell *cell;
    struct ncp_diag *d;
    FILE *f;
    const char *dir;          /* the INI's folder, "" for the current one */
    unsigned line;            /* of the line last read */
    int failed;
    int others;               /* sections other than [CHANNEL_n] */
    char first_other[64];
    unsigned first_other_line;
    int cur;                  /* the index in cell->ch of the section being read, -1 */
};

static int fail(struct cell_read *r, unsigned line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(struct cell_read *r, unsigned line, const char *fmt, ...)
{
    if (r->failed)
        return 0;
    r->failed = 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->d->msg, sizeof r->d->msg, fmt, ap);
    va_end(ap);
    r->d->line = line;
    r->d->code = NCP_ERR_SEMANTIC;
    return 0;
}

/* "CHANNEL_n" with n in 0..NCP_CELL_MAX-1: n; -1 for another section,
 * -2 for CHANNEL_ with a bad number. */
static int channel_section(const char *name)
{
    if (strncasecmp(name, "CHANNEL_", 8) != 0)
        return -1;
    char *end;
    long n = strtol(name + 8, &end, 10);
    if (end == name + 8 || *end || n < 0 || n >= NCP_CELL_MAX || name[8] == '+' ||
        name[8] == '-' || name[8] == ' ')
        return -2;
    return (int)n;
}

/* A section opens as its line is read: [CHANNEL_n] gets its slot (kept
 * in ascending order), so that a section with no CONFIG is seen too. */
static void open_section(struct cell_read *r, const char *name)
{
    struct ncp_cell *c = r->cell;
    int num = channel_section(name);
    r->cur = -1;
    if (num == -1) {
        if (!r->others++) {
            snprintf(r->first_other, sizeof r->first_other, "%s", name);
            r->first_other_line = r->line;
        }
        return;
    }
    if (num == -2) {
        fail(r, r->line, "[%s]: channels are [CHANNEL_0] .. [CHANNEL_%d]", name,
             NCP_CELL_MAX - 1);
        return;
    }
    for (int k = 0; k < c->n; k++)
        if (c->ch[k].num == num) {
            fail(r, r->line, "[CHANNEL_%d] given twice (first on line %u); each channel once",
                 num, c->ch[k].line);
            return;
        }
    int at = c->n++;
    while (at > 0 && c->ch[at - 1].num > num) {
        c->ch[at] = c->ch[at - 1];
        at--;
    }
    memset(&c->ch[at], 0, sizeof c->ch[at]);
    c->ch[at].num = num;
    c->ch[at].backend = -1;
    c->ch[at].line = r->line;
    r->cur = at;
}

static char *read_line(char *str, int n, void *stream)
{
    struct cell_read *r = stream;
    char *s = fgets(str, n, r->f);
    if (!s)
        return NULL;
    r->line++;
    const char *p = s + strspn(s, " \t");
    const char *close = *p == '[' ? strchr(p, ']') : NULL;
    if (close && !r->failed) {
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)(close - p - 1), p + 1);
        open_section(r, name);
    }
    return s;
}

/* BACKEND: sim, lcm, socketcan or socketcan:IFACE (as --backend says it) */
static int backend_value(struct ncp_cell_channel *ch, const char *v)
{
    if (!strcasecmp(v, "sim") || !strcasecmp(v, "lcm")) {
        ch->backend = !strcasecmp(v, "sim") ? NCP_BACKEND_SIM : NCP_BACKEND_LCM;
        return 0;
    }
    if (strncasecmp(v, "socketcan", 9) != 0 || (v[9] && v[9] != ':'))
        return -1;
    const char *ifc = v[9] ? v + 10 : "";
    if (v[9] && (!*ifc || strlen(ifc) >= sizeof ch->interface || strpbrk(ifc, " \t/:")))
        return -1;
    ch->backend = NCP_BACKEND_SOCKETCAN;
    snprintf(ch->interface, sizeof ch->interface, "%s", ifc);
    return 0;
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    struct cell_read *r = user;
    if (r->failed)
        return 1;
    if (channel_section(section) == -1)
        return 1;   /* a machine INI, or a mixed file: decided at the end */
    if (r->cur < 0)
        return 1;   /* its section was refused already */
    struct ncp_cell_channel *ch = &r->cell->ch[r->cur];
    if (!ncp_ini_key_find(section, name))
        return fail(r, r->line, "[%s] %s: unknown key (a channel has CONFIG, BACKEND and DP)",
                    section, name);
    unsigned *at = !strcasecmp(name, "CONFIG")    ? &ch->config_line
                   : !strcasecmp(name, "BACKEND") ? &ch->backend_line
                                                  : &ch->dp_line;
    if (*at)
        return fail(r, r->line, "[%s] %s given twice (first on line %u); each key once",
                    section, name, *at);
    *at = r->line;
    if (at == &ch->config_line) {
        if (!*value)
            return fail(r, r->line, "[%s] CONFIG is empty: it names the channel's machine INI",
                        section);
        int w = value[0] == '/' || !*r->dir
                    ? snprintf(ch->config, sizeof ch->config, "%s", value)
                    : snprintf(ch->config, sizeof ch->config, "%s/%s", r->dir, value);
        if (w < 0 || (size_t)w >= sizeof ch->config)
            return fail(r, r->line, "[%s] CONFIG: path too long", section);
    } else if (at == &ch->backend_line) {
        if (backend_value(ch, value))
            return fail(r, r->line, "[%s] BACKEND: bad value '%s' (sim, socketcan, "
                                    "socketcan:IFACE or lcm)", section, value);
    } else {
        double dp;
        if (ncp_ini_number(value, 1, 5, &dp) || dp != (int)dp)
            return fail(r, r->line, "[%s] DP: bad value '%s' (a distribution point, a whole "
                                    "number from 1 to 5)", section, value);
        ch->dp = (int)dp;
    }
    return 1;
}

int ncp_cell_load(struct ncp_cell *cell, const char *path, struct ncp_diag *d)
{
    memset(cell, 0, sizeof *cell);
    memset(d, 0, sizeof *d);
    char dir[NCP_CELL_PATH_MAX];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 0, path);
    if (slash && slash == path)
        snprintf(dir, sizeof dir, "/");
    struct cell_read r = { .cell = cell, .d = d, .dir = dir, .cur = -1 };
    if (!(r.f = fopen(path, "r")))
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read the INI"), -1;
    int line = ini_parse_stream(read_line, &r, on_key, &r);
    fclose(r.f);
    if (line < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read the INI"), -1;
    if (!cell->n && !r.failed)
        return 0;   /* a machine INI (its own reader says what is wrong in it) */
    if (line > 0 && !r.failed)
        fail(&r, (unsigned)line, "not a line of an INI ([SECTION] or KEY = VALUE)");
    if (!r.failed && r.others)
        fail(&r, r.first_other_line, "[%s] beside [CHANNEL_n] sections: a channels INI "
                                     "names each channel's machine INI (CONFIG), the "
                                     "machine's settings go there", r.first_other);
    for (int k = 0; !r.failed && k < cell->n; k++)
        if (!cell->ch[k].config_line)
            fail(&r, cell->ch[k].line, "[CHANNEL_%d] has no CONFIG (the channel's machine INI)",
                 cell->ch[k].num);
    if (r.failed) {
        cell->n = 0;
        return -1;
    }
    return 1;
}

int ncp_cell_apply(const struct ncp_cell_channel *ch, struct ncp_machine_cfg *cfg,
                   struct ncp_diag *d)
{
    if (ch->backend >= 0)
        cfg->backend = (enum ncp_backend_kind)ch->backend;
    if (ch->interface[0])
        snprintf(cfg->can.interface, sizeof cfg->can.interface, "%s", ch->interface);
    if (!ch->dp)
        return NCP_OK;
    if (cfg->backend != NCP_BACKEND_LCM)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, ch->dp_line, 0,
                            "[CHANNEL_%d] DP goes with BACKEND = lcm: channel %d runs on %s",
                            ch->num, ch->num,
                            cfg->backend == NCP_BACKEND_SIM ? "the simulated machine"
                                                            : "CAN drives (socketcan)");
    cfg->lcm.dp = ch->dp;
    return NCP_OK;
}
