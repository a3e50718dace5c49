/* [RS274NGC] of a LinuxCNC INI, read as rs274 -i reads it. rs274 -i itself
 * reads SUBROUTINE_PATH, REMAP, INI_VARS, OWORD_NARGS, ORIENT_OFFSET and
 * DISABLE_FANUC_STYLE_SUB; PARAMETER_FILE, USER_M_PATH and the
 * logging keys are its task's or GUI's, so they change nothing in rs274 -g
 * and are taken without effect here; any other key would change what rs274
 * prints in a way ncpar does not follow, so it is refused. rs274 -i also
 * reads a few keys of the machine's sections (the tool change, the units,
 * wrapped rotaries): set to anything but their default, they are refused
 * too, the rest of those sections being the machine's. */
#include "rs274_ini.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *const no_effect[] = {
    "PARAMETER_FILE", "USER_M_PATH", "FEATURES", "LOG_LEVEL", "LOG_FILE",
    "ON_ABORT_COMMAND", "RS274NGC_STARTUP_CODE", "HAL_PIN_VARS",
    "DEBUG", /* rs274 reads [EMC]DEBUG, not this one */
};

enum section { SEC_OTHER, SEC_RS274NGC, SEC_EMCIO, SEC_TRAJ, SEC_AXIS_ABC };

static int ini_true(const char *v)
{
    return !strcasecmp(v, "TRUE") || !strcasecmp(v, "YES") || !strcasecmp(v, "ON") ||
           !strcmp(v, "1");
}

/* A machine section's key that rs274 -i reads: 1 when its value is not the
 * default that ncpar follows. */
static int machine_key_changes(enum section sec, const char *key, const char *value)
{
    switch (sec) {
    case SEC_EMCIO:
        if (!strcmp(key, "TOOL_CHANGE_AT_G30") || !strcmp(key, "TOOL_CHANGE_QUILL_UP") ||
            !strcmp(key, "TOOL_CHANGE_WITH_SPINDLE_ON") || !strcmp(key, "RANDOM_TOOLCHANGER"))
            return ini_true(value);
        return 0;
    case SEC_TRAJ:
        /* LINEAR_UNITS sets rs274 -g's external unit, which nothing it
         * prints depends on (tool offsets, #5221, #5403 and G92's measured
         * alike with mm and inch) */
        if (!strcmp(key, "SPINDLES"))
            return atoi(value) != 1;
        return 0;
    case SEC_AXIS_ABC:
        if (!strcmp(key, "WRAPPED_ROTARY"))
            return ini_true(value);
        return !strcmp(key, "LOCKING_INDEXER_JOINT");
    default:
        return 0;
    }
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + len, 1, cap - len - 1, f)) > 0) {
        len += got;
        if (len + 1 == cap) {
            char *more = cap < (64u << 20) ? realloc(buf, cap *= 2) : NULL;
            if (!more) {
                free(buf);
                buf = NULL;
            }
            buf = more;
        }
    }
    if (buf)
        buf[len] = '\0';
    if (ferror(f)) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
}

/* The INI's folders, relative ones taken from the INI's own folder (LinuxCNC
 * runs from the configuration's folder). */
static char *absolute_dirs(const char *ini_path, const char *value)
{
    const char *slash = strrchr(ini_path, '/');
    size_t base = slash ? (size_t)(slash - ini_path) : 0;
    size_t cap = strlen(value) * 2 + 64, len = 0;
    for (const char *p = value; *p; p++)
        cap += *p == ':' ? base + 2 : 0;
    cap += base + 2;
    char *out = malloc(cap);
    if (!out)
        return NULL;
    const char *p = value;
    while (*p) {
        const char *end = strchr(p, ':');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (len)
            out[len++] = ':';
        if (n && p[0] != '/' && slash)
            len += (size_t)snprintf(out + len, cap - len, "%.*s/", (int)base, ini_path);
        len += (size_t)snprintf(out + len, cap - len, "%.*s", (int)n, p);
        p = end ? end + 1 : p + n;
    }
    out[len] = '\0';
    return out;
}

/* machine: the machine INI of run and serve, whose reader took every key
 * already (ncpar.ini(5)); its machine sections are the NCK's, not keys that
 * change what rs274 -g would print. */
static int load(const char *path, struct rs274_ini *ini, int machine)
{
    memset(ini, 0, sizeof *ini);
    ini->text = read_file(path);
    if (!ini->text) {
        fprintf(stderr, "%s: error: cannot read: %s\n", path, strerror(errno ? errno : EIO));
        return -1;
    }
    enum section sec = SEC_OTHER;
    char sec_name[32] = "";
    const char *section = NULL;
    int cap = 0, vcap = 0;
    ini->ini_vars = 1;
    uint32_t line = 0;
    char *next = ini->text;
    while (next) {
        char *s = next;
        line++;
        next = strchr(s, '\n');
        if (next)
            *next++ = '\0';
        s = trim(s);
        if (!*s || *s == '#' || *s == ';')
            continue;
        if (*s == '[') {
            sec = !strcmp(s, "[RS274NGC]") ? SEC_RS274NGC
                  : !strcmp(s, "[EMCIO]")  ? SEC_EMCIO
                  : !strcmp(s, "[TRAJ]")   ? SEC_TRAJ
                  : (!strcmp(s, "[AXIS_A]") || !strcmp(s, "[AXIS_B]") || !strcmp(s, "[AXIS_C]"))
                      ? SEC_AXIS_ABC
                      : SEC_OTHER;
            snprintf(sec_name, sizeof sec_name, "%s", s);
            char *close = strchr(s, ']');
            if (close)
                *close = '\0';
            section = s + 1;
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq && sec != SEC_RS274NGC)
            continue;
        if (!eq) {
            fprintf(stderr, "%s:%u: error: [RS274NGC] line without '=': %s\n", path, line, s);
            return -1;
        }
        *eq = '\0';
        char *key = trim(s), *value = trim(eq + 1);
        if (section) {
            if (ini->n_vars == vcap) {
                vcap = vcap ? vcap * 2 : 32;
                struct ncp_ini_var *more = realloc(ini->vars, (size_t)vcap * sizeof *more);
                if (!more)
                    return fprintf(stderr, "%s: error: out of memory\n", path), -1;
                ini->vars = more;
            }
            ini->vars[ini->n_vars++] = (struct ncp_ini_var){ section, key, value };
        }
        if (sec == SEC_OTHER)
            continue;
        if (sec != SEC_RS274NGC) {
            if (!machine && machine_key_changes(sec, key, value)) {
                fprintf(stderr, "%s:%u: error: %s%s = %s changes what rs274 -i makes of a "
                        "program; ncpar does not follow it\n", path, line, sec_name, key, value);
                return -1;
            }
            continue;
        }
        if (!strcmp(key, "REMAP")) {
            if (ini->n_remaps == cap) {
                cap = cap ? cap * 2 : 8;
                struct ncp_remap_line *more = realloc(ini->remaps, (size_t)cap * sizeof *more);
                if (!more)
                    return fprintf(stderr, "%s: error: out of memory\n", path), -1;
                ini->remaps = more;
            }
            ini->remaps[ini->n_remaps++] = (struct ncp_remap_line){ value, path, line };
        } else if (!strcmp(key, "INI_VARS")) {
            ini->ini_vars = ini_true(value);
        } else if (!strcmp(key, "DISABLE_FANUC_STYLE_SUB")) {
            ini->no_fanuc_subs = ini_true(value);
        } else if (!strcmp(key, "OWORD_NARGS")) {
            ini->oword_nargs = ini_true(value);
        } else if (!strcmp(key, "ORIENT_OFFSET")) {
            char *end = NULL;
            ini->orient_offset = strtod(value, &end);
            if (end == value || *trim(end) || !isfinite(ini->orient_offset)) {
                fprintf(stderr, "%s:%u: error: [RS274NGC]ORIENT_OFFSET = %s: a number of "
                        "degrees expected\n", path, line, value);
                return -1;
            }
        } else if (!strcmp(key, "SUBROUTINE_PATH")) {
            free(ini->sub_path);
            if (!(ini->sub_path = absolute_dirs(path, value)))
                return fprintf(stderr, "%s: error: out of memory\n", path), -1;
        } else {
            size_t k = 0;
            while (k < sizeof no_effect / sizeof no_effect[0] && strcmp(key, no_effect[k]) != 0)
                k++;
            if (k == sizeof no_effect / sizeof no_effect[0] && !machine) {
                fprintf(stderr, "%s:%u: error: [RS274NGC]%s is not supported by ncpar\n", path,
                        line, key);
                return -1;
            }
        }
    }
    return 0;
}

int rs274_ini_load(const char *path, struct rs274_ini *ini)
{
    return load(path, ini, 0);
}

int rs274_ini_load_machine(const char *path, struct rs274_ini *ini)
{
    return load(path, ini, 1);
}

void rs274_ini_free(struct rs274_ini *ini)
{
    free(ini->sub_path);
    free(ini->remaps);
    free(ini->vars);
    free(ini->text);
    memset(ini, 0, sizeof *ini);
}

char *rs274_ini_join_paths(const char *cli, const char *ini)
{
    if (!cli && !ini)
        return NULL;
    size_t n = (cli ? strlen(cli) : 0) + (ini ? strlen(ini) : 0) + 2;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s%s%s", cli ? cli : "", cli && ini ? ":" : "", ini ? ini : "");
    return out;
}

int rs274_ini_apply(const struct rs274_ini *ini, struct ncp_analyzer_cfg *acfg, char **joined)
{
    *joined = NULL;
    if (ini->sub_path) {
        *joined = rs274_ini_join_paths(acfg->subroutine_path, ini->sub_path);
        if (!*joined)
            return fprintf(stderr, "cnc-run: out of memory\n"), -1;
        acfg->subroutine_path = *joined;
    }
    if (ini->ini_vars) {
        acfg->ini_vars = ini->vars;
        acfg->n_ini_vars = ini->n_vars;
    }
    acfg->remaps = ini->remaps;
    acfg->n_remaps = ini->n_remaps;
    acfg->oword_nargs = ini->oword_nargs;
    acfg->orient_offset = ini->orient_offset;
    acfg->no_fanuc_subs = ini->no_fanuc_subs;
    return 0;
}

int rs274_ini_machine(const char *path, const char *user_m_dirs, struct rs274_ini *ini,
                      struct ncp_analyzer_cfg *acfg, char **joined)
{
    memset(ini, 0, sizeof *ini);
    *joined = NULL;
    if (user_m_dirs && *user_m_dirs)
        acfg->user_m_dirs = user_m_dirs;
    if (!path)
        return 0;
    if (rs274_ini_load_machine(path, ini) != 0 || rs274_ini_apply(ini, acfg, joined) != 0)
        return -1;
    if (!ini->n_remaps)
        return 0;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    struct ncp_analyzer *a = ncp_analyzer_new(acfg, &d);
    if (a) {
        ncp_analyzer_free(a);
        return 0;
    }
    if (d.line)
        fprintf(stderr, "%s:%u:%u: error: %s\n", d.file ? d.file : path, d.line,
                d.col ? (unsigned)d.col : 1u, d.msg);
    else
        fprintf(stderr, "%s: error: %s\n", d.file ? d.file : path, d.msg);
    return -1;
}
