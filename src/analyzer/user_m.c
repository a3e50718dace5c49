/* LinuxCNC's user M codes: M100..M199 run the machine's executable file of
 * that name. Which ones exist is found once, when the interpreter is made,
 * as LinuxCNC's task finds them when it starts: a code without one is
 * refused at its block, a code with one becomes a USER_M call. */
#include "stages.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int ncp_user_m_find(const char *dirs, int code, char *out, size_t len)
{
    if (!dirs || code < 100 || code > 199)
        return -1;
    for (const char *p = dirs; *p;) {
        size_t n = strcspn(p, ":");
        struct stat st;
        int w = snprintf(out, len, "%.*s/M%d", (int)n, p, code);
        /* LinuxCNC takes a file its owner may run */
        if (n && w > 0 && (size_t)w < len && stat(out, &st) == 0 && S_ISREG(st.st_mode) &&
            (st.st_mode & S_IXUSR))
            return 0;
        p += n;
        if (*p == ':')
            p++;
    }
    if (len)
        out[0] = '\0';
    return -1;
}

void ncp_user_m_scan(struct ncp_analyzer *a)
{
    a->user_m[0] = a->user_m[1] = 0;
    if (!a->cfg.user_m_dirs || !*a->cfg.user_m_dirs)
        return;
    char path[4096];
    for (unsigned k = 0; k < 100; k++)
        if (ncp_user_m_find(a->cfg.user_m_dirs, 100 + (int)k, path, sizeof path) == 0)
            a->user_m[k / 64] |= 1ull << (k % 64);
}
