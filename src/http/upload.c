/* POST /upload: a program from the browser's computer into the NCK's program
 * folder, on the panel's server thread (libwebsockets' callback mount).
 *
 * The verdict on token, read-only, name and announced size is reached when
 * the headers are in; the body is read either way (a refused request still
 * gets its answer, not a reset) but only a good one is written, to a hidden
 * temporary file streamed as it arrives. At the end it becomes the program:
 * link() when it must not replace one (atomic: two uploads of one name cannot
 * both win), rename() when the operator asked to overwrite. */
#include "server_int.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <libwebsockets.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* the program folder ([DISPLAY] PROGRAM_PREFIX: at most 511 characters) and
 * a name */
#define UPLOAD_PATH_MAX 640

struct upload {
    int open;                       /* fd is the temporary file */
    int fd;
    char tmp[UPLOAD_PATH_MAX];      /* in the program folder, hidden */
    char name[NCP_HTTP_UPLOAD_NAME_MAX + 1];
    char path[UPLOAD_PATH_MAX];     /* name in the program folder */
    int overwrite;
    unsigned status;                /* 0: good so far; else the HTTP status to answer */
    char why[200];
    size_t got;
};

static void discard(struct upload *u)
{
    if (u->open) {
        close(u->fd);
        unlink(u->tmp);
        u->open = 0;
    }
}

static void refuse(const struct ncp_http_floor *f, struct upload *u, unsigned status,
                   enum ncp_http_stat st, const char *why)
{
    if (u->status)
        return;   /* counted once, for the first reason */
    u->status = status;
    snprintf(u->why, sizeof u->why, "%s", why);
    f->count(f->ctx, st);
    discard(u);
}

/* The answer, in one write: small enough for the socket's buffer. */
static int answer(struct lws *wsi, struct upload *u)
{
    char body[512];
    size_t n = 0;
    unsigned status = u->status ? u->status : HTTP_STATUS_OK;
    if (u->status) {
        n = (size_t)snprintf(body, sizeof body, "{\"ok\": false, \"reason\": ");
        ncp_http_json_string(body, sizeof body - 2, &n, u->why, strlen(u->why));
    } else {
        n = (size_t)snprintf(body, sizeof body, "{\"ok\": true, \"name\": ");
        ncp_http_json_string(body, sizeof body - 2, &n, u->name, strlen(u->name));
    }
    body[n++] = '}';
    unsigned char buf[LWS_PRE + 1024];
    unsigned char *start = buf + LWS_PRE, *p = start, *end = buf + sizeof buf - 1;
    if (lws_add_http_common_headers(wsi, status, "application/json", n, &p, end) ||
        lws_finalize_write_http_header(wsi, start, &p, end))
        return -1;
    unsigned char out[LWS_PRE + sizeof body];
    memcpy(out + LWS_PRE, body, n);
    if (lws_write(wsi, out + LWS_PRE, n, LWS_WRITE_HTTP_FINAL) < (int)n)
        return -1;
    return lws_http_transaction_completed(wsi) ? -1 : 0;
}

/* The headers are in: the verdict on everything but the content. */
static void begin(const struct ncp_http_floor *f, struct lws *wsi, struct upload *u)
{
    memset(u, 0, sizeof *u);
    char arg[NCP_HTTP_UPLOAD_NAME_MAX + 16], why[200];
    if (!f->token_ok(f->ctx, wsi)) {
        refuse(f, u, HTTP_STATUS_FORBIDDEN, NCP_HTTP_STAT_NO_TOKEN,
               "no valid token: this panel may only watch");
        return;
    }
    if (f->opts->readonly) {
        refuse(f, u, HTTP_STATUS_FORBIDDEN, NCP_HTTP_STAT_READONLY,
               "the panel is read-only (--http-readonly)");
        return;
    }
    if (lws_hdr_total_length(wsi, WSI_TOKEN_POST_URI) <= 0) {
        refuse(f, u, HTTP_STATUS_METHOD_NOT_ALLOWED, NCP_HTTP_STAT_UPLOAD_BAD,
               "an upload is a POST");
        return;
    }
    const char *name = lws_get_urlarg_by_name(wsi, "name=", arg, (int)sizeof arg);
    if (!name || !ncp_http_upload_name_ok(name, why, sizeof why)) {
        refuse(f, u, HTTP_STATUS_BAD_REQUEST, NCP_HTTP_STAT_UPLOAD_BAD,
               name ? why : "no name= for the program");
        return;
    }
    snprintf(u->name, sizeof u->name, "%s", name);
    const char *dir = f->opts->program_dir;
    if (ncp_http_program_path(dir, u->name, u->path, sizeof u->path) ||
        ncp_http_program_path(dir, ".upload-XXXXXX", u->tmp, sizeof u->tmp)) {
        refuse(f, u, HTTP_STATUS_INTERNAL_SERVER_ERROR, NCP_HTTP_STAT_UPLOAD_BAD,
               "the program folder's path is too long");
        return;
    }
    const char *ow = lws_get_urlarg_by_name(wsi, "overwrite=", arg, (int)sizeof arg);
    u->overwrite = ow && !strcmp(ow, "1");
    char len[32];
    if (lws_hdr_copy(wsi, len, (int)sizeof len, WSI_TOKEN_HTTP_CONTENT_LENGTH) > 0 &&
        strtoull(len, NULL, 10) > NCP_HTTP_UPLOAD_MAX) {
        snprintf(why, sizeof why, "%s is too large (%s bytes, at most %u)", u->name, len,
                 NCP_HTTP_UPLOAD_MAX);
        refuse(f, u, HTTP_STATUS_REQ_ENTITY_TOO_LARGE, NCP_HTTP_STAT_OVERSIZED, why);
        return;
    }
    if (!u->overwrite && access(u->path, F_OK) == 0) {
        snprintf(why, sizeof why, "%s exists: upload it again with overwrite to replace it",
                 u->name);
        refuse(f, u, HTTP_STATUS_CONFLICT, NCP_HTTP_STAT_UPLOAD_BAD, why);
        return;
    }
    u->fd = mkstemp(u->tmp);
    u->open = u->fd >= 0;
    if (u->open)
        (void)fchmod(u->fd, 0644);   /* a program as any other, not mkstemp's 0600 */
    if (!u->open) {
        snprintf(why, sizeof why, "cannot write in the program folder %s: %s",
                 dir && dir[0] ? dir : "(serve's working directory)", strerror(errno));
        refuse(f, u, HTTP_STATUS_INTERNAL_SERVER_ERROR, NCP_HTTP_STAT_UPLOAD_BAD, why);
    }
}

static void take_body(const struct ncp_http_floor *f, struct upload *u, const char *in, size_t len)
{
    if (u->status)
        return;
    u->got += len;
    if (u->got > NCP_HTTP_UPLOAD_MAX) {
        char why[200];
        snprintf(why, sizeof why, "%s is too large (over %u bytes)", u->name,
                 NCP_HTTP_UPLOAD_MAX);
        refuse(f, u, HTTP_STATUS_REQ_ENTITY_TOO_LARGE, NCP_HTTP_STAT_OVERSIZED, why);
        return;
    }
    if (memchr(in, 0, len)) {
        refuse(f, u, HTTP_STATUS_BAD_REQUEST, NCP_HTTP_STAT_UPLOAD_BAD,
               "not a text file (it holds NUL bytes)");
        return;
    }
    while (len) {
        ssize_t w = write(u->fd, in, len);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            char why[200];
            snprintf(why, sizeof why, "cannot write %s: %s", u->name, strerror(errno));
            refuse(f, u, HTTP_STATUS_INTERNAL_SERVER_ERROR, NCP_HTTP_STAT_UPLOAD_BAD, why);
            return;
        }
        in += w;
        len -= (size_t)w;
    }
}

static void finish(const struct ncp_http_floor *f, struct upload *u)
{
    if (u->status)
        return;
    if (u->got == 0) {
        refuse(f, u, HTTP_STATUS_BAD_REQUEST, NCP_HTTP_STAT_UPLOAD_BAD, "the file is empty");
        return;
    }
    int rc = close(u->fd);
    u->open = 0;
    if (rc == 0)
        rc = u->overwrite ? rename(u->tmp, u->path) : link(u->tmp, u->path);
    int err = errno;
    unlink(u->tmp);   /* after link(), the program keeps its own name */
    if (rc) {
        char why[200];
        if (err == EEXIST)
            snprintf(why, sizeof why, "%s exists: upload it again with overwrite to replace it",
                     u->name);
        else
            snprintf(why, sizeof why, "cannot store %s: %s", u->name, strerror(err));
        refuse(f, u, err == EEXIST ? HTTP_STATUS_CONFLICT : HTTP_STATUS_INTERNAL_SERVER_ERROR,
               NCP_HTTP_STAT_UPLOAD_BAD, why);
        return;
    }
    f->count(f->ctx, NCP_HTTP_STAT_UPLOADS);
}

int ncp_http_on_upload(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                       size_t len)
{
    const struct ncp_http_floor *f = ncp_http_floor_of(wsi);
    struct upload *u = user;
    switch (reason) {
    case LWS_CALLBACK_HTTP:
        begin(f, wsi, u);
        /* a body follows a POST; anything else is answered now */
        if (lws_hdr_total_length(wsi, WSI_TOKEN_POST_URI) <= 0)
            return answer(wsi, u);
        {
            char cl[32];
            if (lws_hdr_copy(wsi, cl, (int)sizeof cl, WSI_TOKEN_HTTP_CONTENT_LENGTH) <= 0 ||
                !strcmp(cl, "0")) {
                finish(f, u);
                return answer(wsi, u);
            }
        }
        return 0;
    case LWS_CALLBACK_HTTP_BODY:
        take_body(f, u, in, len);
        return 0;
    case LWS_CALLBACK_HTTP_BODY_COMPLETION:
        finish(f, u);
        return answer(wsi, u);
    case LWS_CALLBACK_CLOSED_HTTP:
        if (u)
            discard(u);
        return 0;
    default:
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
}

size_t ncp_http_upload_session_size(void)
{
    return sizeof(struct upload);
}

int ncp_http_sweep_uploads(const char *folder, int max_age_s)
{
    DIR *dir = opendir(folder && folder[0] ? folder : ".");
    if (!dir)
        return 0;
    int fd = dirfd(dir);
    int removed = 0;
    time_t now = time(NULL);
    struct dirent *e;
    while ((e = readdir(dir))) {
        struct stat st;
        /* mkstemp's names only: ".upload-" and six characters */
        if (strncmp(e->d_name, ".upload-", 8) != 0 || strlen(e->d_name) != 14 ||
            fstatat(fd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode) ||
            now - st.st_mtime < max_age_s)
            continue;
        removed += unlinkat(fd, e->d_name, 0) == 0;
    }
    closedir(dir);
    return removed;
}
