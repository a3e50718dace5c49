/* The user's own files (userdata.h). */
#include "userdata.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* mkdir -p, the folders it makes 0700 (a history names the programs run) */
static int make_folders(char *dir)
{
    for (char *p = dir + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = 0;
        int rc = mkdir(dir, 0700);
        *p = '/';
        if (rc != 0 && errno != EEXIST)
            return -1;
    }
    return mkdir(dir, 0700) != 0 && errno != EEXIST ? -1 : 0;
}

int ncp_cli_default_history(char *out, size_t len, char *why, size_t wl)
{
    const char *xdg = getenv("XDG_DATA_HOME"), *home = getenv("HOME");
    char dir[4096];
    int n;
    if (xdg && xdg[0] == '/')   /* the XDG rule: a relative one is ignored */
        n = snprintf(dir, sizeof dir, "%s/ncpar", xdg);
    else if (home && home[0] == '/')
        n = snprintf(dir, sizeof dir, "%s/.local/share/ncpar", home);
    else
        return snprintf(why, wl, "neither $XDG_DATA_HOME nor $HOME is set"), -1;
    if (n < 0 || (size_t)n >= sizeof dir || (size_t)n + 16 >= len)
        return snprintf(why, wl, "the data folder's path is too long"), -1;
    if (make_folders(dir) != 0)
        return snprintf(why, wl, "cannot make %s: %s", dir, strerror(errno)), -1;
    snprintf(out, len, "%s/history.jsonl", dir);
    return 0;
}
