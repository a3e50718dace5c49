/* The files behind the panel's Tools and History tabs, read-only, on the
 * worker thread (jobs.c): the tool table the NCK rewrites at each G10 L1
 * and the job history it appends to, the same files `cnc-ctl tool list`
 * and `cnc-ctl history` read. Only these two paths, fixed at start from the
 * machine's INI (or --tool-table): a socket names neither, so nothing else
 * on the host can be read through them. The text goes out as the file has
 * it; the panel parses it as cnc-ctl does. A missing file or one the
 * machine does not keep is an answer with "why", so the tab can say so. */
#include "server_int.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define TOOLS_MAX (256u << 10)      /* a tool table larger than this is not shown */
#define HISTORY_TAIL (64u << 10)    /* the history's last whole lines within this */

/* {"type": T, "path": P|null, "text": X, "why": W} after LWS_PRE bytes. */
static int answer(struct ncp_http_msg *out, const char *type, const char *path,
                  const char *text, size_t n, const char *why)
{
    size_t pl = path ? strlen(path) : 0, wl = strlen(why);
    size_t cap = LWS_PRE + 96 + 6 * (pl + n + wl);
    char *p = malloc(cap);
    if (!p)
        return -1;
    size_t k = LWS_PRE;
    k += (size_t)snprintf(p + k, cap - k, "{\"type\": \"%s\", \"path\": ", type);
    int bad = 0;
    if (path)
        bad |= ncp_http_json_string(p, cap, &k, path, pl);
    else
        k += (size_t)snprintf(p + k, cap - k, "null");
    k += (size_t)snprintf(p + k, cap - k, ", \"text\": ");
    bad |= ncp_http_json_string(p, cap, &k, text, n);
    k += (size_t)snprintf(p + k, cap - k, ", \"why\": ");
    bad |= ncp_http_json_string(p, cap, &k, why, wl);
    k += (size_t)snprintf(p + k, cap - k, "}");
    if (bad || k >= cap) {
        free(p);
        return -1;
    }
    out->buf = (unsigned char *)p;
    out->len = k - LWS_PRE;
    return 0;
}

/* The file's text (malloc'd, NUL-ended) into *text: 0, or -1 with why.
 * Larger than max: refused, or with tail its last max bytes from the first
 * whole line in them. */
static int read_text(const char *path, size_t max, int tail, char **text, size_t *n, char *why,
                     size_t wl)
{
    *text = NULL;
    *n = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(why, wl, "%s: %s", path, fd < 0 ? strerror(errno) : "not a plain file");
        if (fd >= 0)
            close(fd);
        return -1;
    }
    size_t size = (size_t)st.st_size, from = 0;
    if (size > max && !tail) {
        close(fd);
        return snprintf(why, wl, "%s is too large to show (%zu bytes, at most %u)", path, size,
                        TOOLS_MAX), -1;
    }
    if (size > max)
        from = size - max;
    char *buf = malloc(size - from + 1);
    size_t got = 0;
    while (buf && got < size - from) {
        ssize_t r = pread(fd, buf + got, size - from - got, (off_t)(from + got));
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd);
    if (!buf)
        return snprintf(why, wl, "out of memory"), -1;
    buf[got] = 0;
    size_t skip = 0;
    if (from > 0) {
        const char *nl = memchr(buf, '\n', got);
        skip = nl ? (size_t)(nl - buf) + 1 : got;
    }
    memmove(buf, buf + skip, got - skip + 1);
    *text = buf;
    *n = got - skip;
    return 0;
}

int ncp_http_file_answer(const struct ncp_http_paths *paths, enum ncp_http_req r,
                         struct ncp_http_msg *out)
{
    int tools = r == NCP_HTTP_REQ_TOOLS;
    const char *type = tools ? "tools" : "history";
    const char *path = tools ? paths->tool_table : paths->history_file;
    if (!path || !path[0])
        return answer(out, type, NULL, "", 0,
                      tools ? "the machine has no tool table ([EMCIO] TOOL_TABLE or "
                              "--tool-table)"
                            : "the machine keeps no job history (its INI has no [DISPLAY] "
                              "HISTORY_FILE)");
    char why[400], *text;
    size_t n;
    if (read_text(path, tools ? TOOLS_MAX : HISTORY_TAIL, !tools, &text, &n, why, sizeof why)) {
        /* no job has ended yet: an empty history, not a fault */
        int none = !tools && access(path, F_OK) != 0 && errno == ENOENT;
        return answer(out, type, path, "", 0, none ? "" : why);
    }
    int rc = answer(out, type, path, text, n, "");
    free(text);
    return rc;
}
