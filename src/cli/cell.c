/* [CHANNEL_n] CONFIG = machine.ini: which machine each NC channel of a
 * service drives. Machine settings stay in the machine INIs; a file that
 * mixes the two is refused, so that no key is read from the wrong one. */
#include "cell.h"

#include <ini.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

struct cell_read {
    struct ncp_cli_cell *cell;
    const char *dir;          /* the INI's folder, "" for the current one */
    int channels, others;     /* sections of each kind seen */
    char first_other[64];
    char why[PATH_MAX + 128];
};

/* "CHANNEL_n" with n in 0..NCP_CLI_CELL_MAX-1: n; -1 for another section,
 * -2 for CHANNEL_ with a bad number. */
static int channel_section(const char *section)
{
    if (strncasecmp(section, "CHANNEL_", 8) != 0)
        return -1;
    char *end;
    long n = strtol(section + 8, &end, 10);
    if (end == section + 8 || *end || n < 0 || n >= NCP_CLI_CELL_MAX)
        return -2;
    return (int)n;
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    struct cell_read *r = user;
    struct ncp_cli_cell *c = r->cell;
    int num = channel_section(section);
    if (num == -1) {
        if (!r->others++)
            snprintf(r->first_other, sizeof r->first_other, "%s", section);
        return 1;   /* a machine INI, or a mixed file: decided at the end */
    }
    if (num == -2)
        return snprintf(r->why, sizeof r->why, "[%s]: channels are [CHANNEL_0] .. [CHANNEL_%d]",
                        section, NCP_CLI_CELL_MAX - 1), 0;
    if (strcasecmp(name, "CONFIG") != 0)
        return snprintf(r->why, sizeof r->why, "[%s] %s: unknown key (a channel has CONFIG = "
                        "its machine INI)", section, name), 0;
    for (int k = 0; k < c->n; k++)
        if (c->num[k] == num)
            return snprintf(r->why, sizeof r->why, "[%s] CONFIG is given twice", section), 0;
    if (!*value)
        return snprintf(r->why, sizeof r->why, "[%s] CONFIG is empty", section), 0;
    int at = c->n++;
    while (at > 0 && c->num[at - 1] > num) {   /* keep them ascending */
        c->num[at] = c->num[at - 1];
        memcpy(c->config[at], c->config[at - 1], sizeof c->config[at]);
        at--;
    }
    c->num[at] = num;
    int w = value[0] == '/' || !*r->dir
                ? snprintf(c->config[at], sizeof c->config[at], "%s", value)
                : snprintf(c->config[at], sizeof c->config[at], "%s/%s", r->dir, value);
    if (w < 0 || (size_t)w >= sizeof c->config[at])
        return snprintf(r->why, sizeof r->why, "[%s] CONFIG: path too long", section), 0;
    r->channels++;
    return 1;
}

int ncp_cli_cell_load(const char *path, struct ncp_cli_cell *cell)
{
    memset(cell, 0, sizeof *cell);
    char dir[PATH_MAX];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 0, path);
    if (slash && slash == path)
        snprintf(dir, sizeof dir, "/");
    struct cell_read r = { .cell = cell, .dir = dir };
    int line = ini_parse(path, on_key, &r);
    if (line < 0) {
        fprintf(stderr, "%s: error: cannot read the INI\n", path);
        return -1;
    }
    if (line > 0 && r.why[0]) {
        fprintf(stderr, "%s:%d: error: %s\n", path, line, r.why);
        return -1;
    }
    if (line > 0 && r.channels) {
        fprintf(stderr, "%s:%d: error: not a line of an INI ([SECTION] or KEY = VALUE)\n",
                path, line);
        return -1;
    }
    if (!r.channels) {
        cell->n = 0;
        return 0;   /* a machine INI (its own loader reports its errors) */
    }
    if (r.others) {
        fprintf(stderr, "%s: error: [%s] beside [CHANNEL_n] sections: a channels INI names "
                        "each channel's machine INI (CONFIG), the machine's settings go there\n",
                path, r.first_other);
        return -1;
    }
    return 1;
}
