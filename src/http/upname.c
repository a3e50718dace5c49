/* What an uploaded program may be called. The name lands in the NCK's program
 * folder as given, so anything that could reach outside it (a slash, "..",
 * a leading dot or dash) or that the program list would not show is refused
 * with the reason, never quietly rewritten: the operator must find the file
 * under the name they chose. */
#include "ncpar/http.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

int ncp_http_upload_name_ok(const char *name, char *why, size_t wl)
{
    size_t n = strlen(name);
    if (n == 0 || n > NCP_HTTP_UPLOAD_NAME_MAX)
        return snprintf(why, wl, "a program's name has 1 to %d characters",
                        NCP_HTTP_UPLOAD_NAME_MAX), 0;
    if (name[0] == '.' || name[0] == '-')
        return snprintf(why, wl, "a program's name may not start with '%c'", name[0]), 0;
    for (size_t i = 0; i < n; i++) {
        char c = name[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '.' || c == '_' || c == '-' || c == '+'))
        {
            if (c > ' ' && c < 0x7f)
                snprintf(why, wl, "a program's name is letters, digits and . _ - + only "
                         "(no folders): '%c' is not", c);
            else
                snprintf(why, wl, "a program's name is letters, digits and . _ - + only: "
                         "no spaces, control or non-ASCII characters");
            return 0;
        }
    }
    static const char *const ext[] = { ".ngc", ".nc", ".tap" };
    for (size_t k = 0; k < sizeof ext / sizeof ext[0]; k++) {
        size_t e = strlen(ext[k]);
        if (n > e && !strcasecmp(name + n - e, ext[k]))
            return 1;
    }
    return snprintf(why, wl, "a program's name ends in .ngc, .nc or .tap"), 0;
}

int ncp_http_program_path(const char *dir, const char *name, char *out, size_t cap)
{
    int n = name[0] == '/' || !dir || !dir[0]
                ? snprintf(out, cap, "%s", name)
                : snprintf(out, cap, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", name);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}
