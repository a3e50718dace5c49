/* The shipped files' folder: beside the executable, else PREFIX/share/ncpar. */
#include "datadir.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int found(const char *dir, const char *probe)
{
    char path[PATH_MAX];
    int n = snprintf(path, sizeof path, "%s/%s", dir, probe);
    return n > 0 && (size_t)n < sizeof path && access(path, R_OK) == 0;
}

int ncp_cli_data_dir(const char *exe, const char *what, const char *probe, char *out,
                     size_t len)
{
    const char *slash = strrchr(exe, '/');
    int bin_len = slash ? (int)(slash - exe) : 1;
    const char *bin = slash ? exe : ".";
    int n = snprintf(out, len, "%.*s/%s", bin_len, bin, what);
    if (n < 0 || (size_t)n >= len)
        return -1;
    if (found(out, probe))
        return 0;
    n = snprintf(out, len, "%.*s/../share/ncpar/%s", bin_len, bin, what);
    if (n < 0 || (size_t)n >= len)
        return -1;
    /* the messages then name the folder as a user would write it */
    char real[PATH_MAX];
    if (realpath(out, real) && strlen(real) < len)
        memcpy(out, real, strlen(real) + 1);
    return 0;
}
