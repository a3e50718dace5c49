/* The shared secret's file: where it is, made once, refused when others
 * could read it (see ncpar/auth.h). */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <openssl/crypto.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ncpar/auth.h"

int ncp_auth_key_path(char *buf, size_t size, const char *explicit_path, const char *ini,
                      struct ncp_diag *d)
{
    int n;
    const char *xdg = getenv("XDG_CONFIG_HOME"), *home = getenv("HOME");
    if (explicit_path && *explicit_path)
        n = snprintf(buf, size, "%s", explicit_path);
    else if (ini && *ini)
        n = snprintf(buf, size, "%s", ini);
    else if (xdg && *xdg == '/')   /* the XDG rule: a relative one is ignored */
        n = snprintf(buf, size, "%s/ncpar/lcm.key", xdg);
    else if (home && *home)
        n = snprintf(buf, size, "%s/.config/ncpar/lcm.key", home);
    else
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "no key file: neither --key-file, [LCM] KEY_FILE nor $HOME is set"),
               -1;
    if (n < 0 || (size_t)n >= size)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "the key file's path is longer than %zu bytes",
                            size - 1),
               -1;
    return 0;
}

/* mkdir -p of path's folder, the folders it makes 0700. */
static int make_folder_of(const char *path)
{
    char dir[NCP_AUTH_PATH_MAX];
    if (snprintf(dir, sizeof dir, "%s", path) >= (int)sizeof dir)
        return -1;
    char *slash = strrchr(dir, '/');
    if (slash == NULL || slash == dir)
        return 0;
    *slash = 0;
    for (char *p = dir + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = 0;
        if (mkdir(dir, 0700) != 0 && errno != EEXIST)
            return -1;
        *p = '/';
    }
    return mkdir(dir, 0700) != 0 && errno != EEXIST ? -1 : 0;
}

static int create_key(const char *path, struct ncp_diag *d)
{
    if (make_folder_of(path) != 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot make the folder of key file %s: %s",
                            path, strerror(errno)),
               -1;
    uint8_t key[NCP_AUTH_KEY_BYTES];
    if (getrandom(key, sizeof key, 0) != (ssize_t)sizeof key)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "no random bytes for a new key: %s",
                            strerror(errno)),
               -1;
    /* O_EXCL: two services started at once make one key, not two halves */
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) {
        explicit_bzero(key, sizeof key);
        return errno == EEXIST ? 0
                               : (ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                               "cannot create key file %s: %s", path,
                                               strerror(errno)),
                                  -1);
    }
    ssize_t w = write(fd, key, sizeof key);
    explicit_bzero(key, sizeof key);
    if (w != (ssize_t)sizeof key || fsync(fd) != 0) {
        int e = errno;
        close(fd);
        unlink(path);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot write key file %s: %s", path,
                            strerror(e)),
               -1;
    }
    close(fd);
    fprintf(stderr, "ncpar: created key file %s (give it to every client, see docs/security.md)\n", path);
    return 0;
}

/* 32 raw bytes, or 64 hex digits with an optional newline: 0, or -1. */
static int key_of(const uint8_t *buf, size_t n, uint8_t key[NCP_AUTH_KEY_BYTES])
{
    if (n == NCP_AUTH_KEY_BYTES) {
        memcpy(key, buf, n);
        return 0;
    }
    if (n == 2 * (size_t)NCP_AUTH_KEY_BYTES + 1 && buf[n - 1] == '\n')
        n--;
    if (n != 2 * (size_t)NCP_AUTH_KEY_BYTES)
        return -1;
    for (size_t i = 0; i < NCP_AUTH_KEY_BYTES; i++) {
        int hi = OPENSSL_hexchar2int(buf[2 * i]), lo = OPENSSL_hexchar2int(buf[2 * i + 1]);
        if (hi < 0 || lo < 0)
            return -1;
        key[i] = (uint8_t)(hi << 4 | lo);
    }
    return 0;
}

int ncp_auth_load_key(const char *path, int create, uint8_t key[NCP_AUTH_KEY_BYTES],
                      struct ncp_diag *d)
{
    if (create && access(path, F_OK) != 0 && errno == ENOENT && create_key(path, d) != 0)
        return -1;
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0 && errno == ELOOP)
        fd = open(path, O_RDONLY | O_CLOEXEC);   /* a symlink is fine; its target is judged */
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "cannot read key file %s: %s (the NCK's key: see "
                            "docs/security.md)",
                            path, strerror(errno)),
               -1;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "key file %s is not a regular file", path), -1;
    }
    if (st.st_mode & 077) {
        close(fd);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "key file %s has mode %04o: group or others may read or change it "
                            "(chmod 600 %s)",
                            path, (unsigned)(st.st_mode & 07777), path),
               -1;
    }
    uint8_t buf[2 * NCP_AUTH_KEY_BYTES + 2];
    ssize_t n = read(fd, buf, sizeof buf);
    close(fd);
    int rc = n < 0 ? -1 : key_of(buf, (size_t)n, key);
    explicit_bzero(buf, sizeof buf);
    if (rc != 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "key file %s holds no key: 32 bytes, or 64 hex digits, expected",
                            path),
               -1;
    return 0;
}

struct ncp_auth *ncp_auth_open(const char *explicit_path, const char *ini, int create,
                               struct ncp_diag *d)
{
    char path[NCP_AUTH_PATH_MAX];
    uint8_t key[NCP_AUTH_KEY_BYTES];
    if (ncp_auth_key_path(path, sizeof path, explicit_path, ini, d) != 0 ||
        ncp_auth_load_key(path, create, key, d) != 0)
        return NULL;
    struct ncp_auth *a = ncp_auth_new(key);
    explicit_bzero(key, sizeof key);
    if (a == NULL)
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the key of %s", path);
    return a;
}
