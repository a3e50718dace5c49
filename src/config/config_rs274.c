/* The interpreter's keys of a LinuxCNC INI in the machine INI: [RS274NGC]
 * and [DISPLAY] PROGRAM_PREFIX, so that one file configures both the
 * machine and its interpreter, as LinuxCNC's does. The REMAP lines and the
 * subroutine folders are taken here only as text: the interpreter reads
 * them (cnc-run's rs274_ini.c) and refuses a bad one, naming its line,
 * before anything moves. The NCK keeps where the user M codes' programs
 * are: it runs them. */
#include "ncpar/config.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* value's folders (':' between them) into out, each made absolute: "~/"
 * from $HOME, a relative one from the INI's folder (LinuxCNC runs in the
 * configuration's folder). 0, or -1 when out is too small. */
static int absolute_dirs(const char *ini_path, const char *value, char *out, size_t cap)
{
    const char *slash = strrchr(ini_path, '/');
    int base = slash ? (int)(slash - ini_path) : 0;
    const char *home = getenv("HOME");
    size_t len = 0;
    out[0] = '\0';
    for (const char *p = value; *p;) {
        size_t n = strcspn(p, ":");
        int w;
        const char *sep = len ? ":" : "";
        /* a relative folder is taken from the INI's ("/" included); an INI
         * named without a folder is in the current one */
        int rel = n && p[0] != '/' && slash;
        if (n == 0)
            w = 0;
        else if (p[0] == '~' && (n == 1 || p[1] == '/') && home && *home)
            w = snprintf(out + len, cap - len, "%s%s%.*s", sep, home, (int)n - 1, p + 1);
        else
            w = snprintf(out + len, cap - len, "%s%.*s%s%.*s", sep, rel ? base : 0, ini_path,
                         rel ? "/" : "", (int)n, p);
        if (w < 0 || (size_t)w >= cap - len)
            return -1;
        len += (size_t)w;
        p += n;
        if (*p == ':')
            p++;
    }
    return 0;
}

static int folders(const char *ini_path, const char *v, char *dst, size_t cap, char *why,
                   size_t len)
{
    if (!*v || absolute_dirs(ini_path, v, dst, cap) != 0)
        return snprintf(why, len, "folders separated by ':', together at most %zu characters "
                                  "once made absolute", cap - 1), -1;
    return 1;
}

int ncp_rs274_cfg_key(struct ncp_rs274_cfg *r, const char *ini_path, const char *sec,
                      const char *k, const char *v, char *why, size_t len)
{
    if (!strcasecmp(sec, "DISPLAY"))
        return strcasecmp(k, "PROGRAM_PREFIX") != 0
                   ? 0
                   : folders(ini_path, v, r->program_prefix, sizeof r->program_prefix, why, len);
    if (strcasecmp(sec, "RS274NGC") != 0)
        return -2;
    if (!strcasecmp(k, "USER_M_PATH"))
        return folders(ini_path, v, r->user_m_path, sizeof r->user_m_path, why, len);
    /* the interpreter's: checked when cnc-run reads them */
    if (!strcasecmp(k, "REMAP") || !strcasecmp(k, "SUBROUTINE_PATH"))
        return *v ? 1 : (snprintf(why, len, "not empty"), -1);
    if (!strcasecmp(k, "ORIENT_OFFSET")) {
        char *end = NULL;
        double d = strtod(v, &end);
        return end != v && !*end && d >= -1e9 && d <= 1e9
                   ? 1
                   : (snprintf(why, len, "a number of degrees"), -1);
    }
    if (!strcasecmp(k, "INI_VARS") || !strcasecmp(k, "OWORD_NARGS") ||
        !strcasecmp(k, "DISABLE_FANUC_STYLE_SUB")) {
        static const char *const words[] = { "0", "1", "NO", "YES", "FALSE", "TRUE", "OFF", "ON" };
        for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
            if (!strcasecmp(v, words[i]))
                return 1;
        return snprintf(why, len, "0 or 1"), -1;
    }
    return 0;
}

void ncp_rs274_cfg_finish(struct ncp_rs274_cfg *r)
{
    snprintf(r->user_m_dirs, sizeof r->user_m_dirs, "%s%s%s", r->program_prefix,
             r->program_prefix[0] && r->user_m_path[0] ? ":" : "", r->user_m_path);
}
