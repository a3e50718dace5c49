/* LinuxCNC's parameter file (ncpar/analyzer.h): what rs274's
 * restore_parameters and save_parameters read and write, with two
 * differences a machinist gains by: a line that is not "NUMBER VALUE" is an
 * error naming it (rs274 skips it, and the offsets it held silently become
 * 0), and the file is replaced whole (temporary file, fsync, rename) rather
 * than renamed to .bak and rewritten in place. */
#include "num_text.h"
#include "params.h"
#include "save_whole.h"
#include "ncpar/analyzer.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(NCP_VAR_PARAMS == NCP_PARAMS_MAX, "the file holds the interpreter's numbers");

int ncp_var_persistent(int k)
{
    if ((k >= 5161 && k <= 5169) || (k >= 5181 && k <= 5189) || (k >= 5210 && k <= 5220))
        return 1;
    /* G54..G59.3: X Y Z A B C U V W and R at 5221 + 20 n .. 5230 + 20 n */
    return k >= 5221 && k <= 5390 && (k - 5221) % 20 < 10;
}

void ncp_var_file_init(struct ncp_var_file *vf)
{
    memset(vf, 0, sizeof *vf);
    for (int k = 1; k < NCP_VAR_PARAMS; k++)
        vf->listed[k] = (unsigned char)ncp_var_persistent(k);
    vf->value[5220] = 1.0;
}

static int bad_line(struct ncp_diag *d, unsigned line, const char *fmt,
                    const char *arg)
{
    char why[160];
    snprintf(why, sizeof why, fmt, arg);
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0, "%s", why);
}

/* One line: its number and value, or an error. The text is the line
 * without its newline. */
static int parse_line(const char *s, int *num, double *v)
{
    char *end;
    while (*s == ' ' || *s == '\t')
        s++;
    if (!isdigit((unsigned char)*s))
        return -1;
    errno = 0;
    long k = strtol(s, &end, 10);
    if (errno || end == s || (*end != ' ' && *end != '\t'))
        return -1;
    s = end;
    while (*s == ' ' || *s == '\t')
        s++;
    errno = 0;
    *v = strtod(s, &end);
    if (end == s || errno == ERANGE)
        return -1;
    while (*end == ' ' || *end == '\t' || *end == '\r')
        end++;
    if (*end)
        return -1;
    *num = k > 0 && k < NCP_VAR_PARAMS ? (int)k : 0;
    return 0;
}

int ncp_var_file_read(const char *path, struct ncp_var_file *vf, int *existed,
                      struct ncp_diag *d)
{
    ncp_var_file_init(vf);
    *existed = 0;
    FILE *f = fopen(path, "r");
    if (!f && errno == ENOENT)
        return NCP_OK;
    if (!f)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read parameter file %s: %s", path,
                            strerror(errno));
    *existed = 1;
    char buf[512];
    unsigned line = 0;
    int last = 0, rc = NCP_OK;
    while (rc == NCP_OK && fgets(buf, sizeof buf, f)) {
        line++;
        size_t n = strlen(buf);
        if (n == sizeof buf - 1 && buf[n - 1] != '\n') {
            rc = bad_line(d, line, "line too long%s", "");
            break;
        }
        if (n && buf[n - 1] == '\n')
            buf[--n] = '\0';
        if (buf[strspn(buf, " \t\r")] == '\0')
            continue;   /* blank */
        int k = 0;
        double v = 0;
        if (parse_line(buf, &k, &v) != 0)
            rc = bad_line(d, line, "'%.60s' is not a parameter line (NUMBER VALUE)", buf);
        else if (k == 0)
            rc = bad_line(d, line, "parameter number out of range 1..5601 in '%.60s'", buf);
        else if (!isfinite(v))
            rc = bad_line(d, line, "parameter value not a finite number in '%.60s'", buf);
        else if (k <= last)
            rc = bad_line(d, line, "parameter numbers must be in increasing order "
                          "(LinuxCNC's rule), '%.60s' is not", buf);
        else if (k == 5220 && (v < 1 || v > 9 || v != floor(v)))
            rc = bad_line(d, line, "#5220 is the coordinate system, 1 (G54) .. 9 "
                          "(G59.3): '%.60s'", buf);
        if (rc != NCP_OK)
            break;
        vf->value[k] = v;
        vf->listed[k] = 1;
        last = k;
    }
    if (rc == NCP_OK && ferror(f))
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read parameter file %s: %s", path,
                          strerror(errno ? errno : EIO));
    fclose(f);
    return rc;
}

char *ncp_var_file_text(const struct ncp_var_file *vf, size_t *len)
{
    size_t cap = 4096, n = 0;
    char *text = malloc(cap);
    if (!text)
        return NULL;
    text[0] = '\0';
    for (int k = 1; k < NCP_VAR_PARAMS; k++) {
        if (!vf->listed[k])
            continue;
        if (cap - n < 400) {
            char *more = realloc(text, cap * 2);
            if (!more) {
                free(text);
                return NULL;
            }
            text = more;
            cap *= 2;
        }
        n += (size_t)snprintf(text + n, cap - n, "%d\t", k);
        n += (size_t)ncp_num_text(text + n, cap - n - 1, vf->value[k], 0);
        text[n++] = '\n';
        text[n] = '\0';
    }
    *len = n;
    return text;
}

int ncp_var_file_write(const char *path, const struct ncp_var_file *vf, struct ncp_diag *d)
{
    size_t len;
    char *text = ncp_var_file_text(vf, &len);
    if (!text)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "parameter file %s: out of memory", path);
    int rc = ncp_save_whole(path, text, len, "parameter file", d);
    free(text);
    return rc;
}
