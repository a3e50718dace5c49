/* cnc-ctl tool list and tool set: the tool table a serving NCK writes back
 * (its path from the NCK's FILES command). A change goes through the NCK as MDI G10 L1, the
 * way a program's own G10 L1 does, so the NCK's rules decide when it may
 * happen (not while a program runs) and it rewrites the file whole; the
 * list is read from that file on this host. Lengths are mm on the command
 * line and on screen; the file holds inches, as rs274 reads it. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctl.h"
#include "ncpar/num.h"

#define MM_PER_INCH 25.4

static int status_now(struct ctl *c, const char *what)
{
    int rc = ctl_next_status(c, c->timeout);
    if (rc == CTL_NO_ANSWER)
        ctl_no_answer(what, c->timeout);
    return rc < 0 ? CTL_NO_ANSWER : rc;
}

static int in_inches(const ncp_status_t *s)
{
    for (size_t i = 0; i < sizeof s->gcodes / sizeof s->gcodes[0]; i++)
        if (s->gcodes[i] == 200)
            return 1;
    return 0;
}

/* "T2", "2": the tool number, or -1. */
static long tool_number(const char *w)
{
    long t;
    if (toupper((unsigned char)w[0]) == 'T')
        w++;
    return ncp_num_long(w, 10, 1, 99999, &t) == 0 ? t : -1;
}

int ctl_tool_set(struct ctl *c, const char *const *words, int n)
{
    long t = tool_number(words[0]);
    if (t < 0) {
        fprintf(stderr, "cnc-ctl: tool set: a tool number (T1 or 1), not '%s'\n", words[0]);
        return CTL_USAGE;
    }
    int rc = status_now(c, "tool set");
    if (rc != CTL_OK)
        return rc;
    double scale = in_inches(&c->status) ? 1.0 / MM_PER_INCH : 1.0;
    char line[256];
    int k = snprintf(line, sizeof line, "G10 L1 P%ld", t);
    for (int i = 1; i < n; i++) {
        char letter = (char)toupper((unsigned char)words[i][0]);
        const char *v = words[i] + 1;
        if (!*v && i + 1 < n)   /* Z -1.5 as well as Z-1.5 */
            v = words[++i];
        double x;
        if (!strchr("XYZABCUVWDQIJP", letter) || ncp_num_double(v, -1e6, 1e6, &x) != 0) {
            fprintf(stderr, "cnc-ctl: tool set: LETTER VALUE pairs of X Y Z A B C U V W "
                            "(offsets, mm or degrees), D (diameter, mm), Q (orientation), I J "
                            "(angles), not '%s'\n", words[i]);
            return CTL_USAGE;
        }
        if (letter == 'P') {
            fprintf(stderr, "cnc-ctl: tool set: the pocket (P) is not the NCK's to change "
                            "(LinuxCNC's G10 L1 neither): edit the tool table while serve is "
                            "stopped\n");
            return CTL_USAGE;
        }
        int linear = strchr("XYZUVWD", letter) != NULL;
        double out = linear ? x * scale : x;
        if (letter == 'D')   /* G10 L1 takes the radius */
            k += snprintf(line + k, sizeof line - (size_t)k, " R%.17g", out / 2);
        else
            k += snprintf(line + k, sizeof line - (size_t)k, " %c%.17g", letter, out);
        if (k >= (int)sizeof line) {
            fprintf(stderr, "cnc-ctl: tool set: too many values\n");
            return CTL_USAGE;
        }
    }
    if (n < 2) {
        fprintf(stderr, "cnc-ctl: tool set: nothing to set (Z -1.5, D 6, ...)\n");
        return CTL_USAGE;
    }
    ncp_command_t cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.kind = NCP_COMMAND_T_MDI;
    snprintf((char *)cmd.text, sizeof cmd.text, "%s", line);
    rc = ctl_command(c, &cmd);
    return rc == CTL_OK ? ctl_wait_done(c, NCP_STATUS_T_MDI, "the tool table change") : rc;
}

struct tool_line {
    long t, p;
    int has[26];
    double v[26];
    char comment[200];
};

/* One LinuxCNC tool table line: T P and the letters, then ;comment. 0, or
 * -1 for a line that is no tool (a comment, blank). */
static int parse_tool(const char *s, struct tool_line *tl)
{
    memset(tl, 0, sizeof *tl);
    tl->t = -1;
    const char *semi = strchr(s, ';');
    if (semi) {
        snprintf(tl->comment, sizeof tl->comment, "%s", semi + 1);
        tl->comment[strcspn(tl->comment, "\r\n")] = 0;
    }
    const char *end = semi ? semi : s + strlen(s);
    for (const char *p = s; p < end;) {
        while (p < end && isspace((unsigned char)*p))
            p++;
        if (p >= end)
            break;
        int letter = toupper((unsigned char)*p++);
        char *e;
        double x = strtod(p, &e);
        if (e == p || letter < 'A' || letter > 'Z')
            return -1;
        p = e;
        if (letter == 'T')
            tl->t = lround(x);
        else if (letter == 'P')
            tl->p = lround(x);
        tl->has[letter - 'A'] = 1;
        tl->v[letter - 'A'] = x;
    }
    return tl->t >= 0 ? 0 : -1;
}

static void json_str(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            printf("\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            printf("\\u%04x", (unsigned char)*s);
        else
            putchar(*s);
    }
    putchar('"');
}

static void print_tool(const struct tool_line *tl, int json, int first)
{
    static const char letters[] = "XYZABCUVWDIJQ";
    if (json) {
        printf("%s{\"tool\": %ld, \"pocket\": %ld", first ? "" : ", ", tl->t, tl->p);
        for (const char *l = letters; *l; l++) {
            int i = *l - 'A';
            if (!tl->has[i])
                continue;
            int linear = strchr("XYZUVWD", *l) != NULL;
            printf(", \"%s\": %.6f", *l == 'D' ? "diameter" : (char[]){ (char)tolower(*l), 0 },
                   linear ? tl->v[i] * MM_PER_INCH : tl->v[i]);
        }
        printf(", \"comment\": ");
        json_str(tl->comment);
        putchar('}');
        return;
    }
    printf("T%-4ld P%-4ld", tl->t, tl->p);
    for (const char *l = letters; *l; l++) {
        int i = *l - 'A';
        if (tl->has[i])
            printf(" %c %.4f", *l, strchr("XYZUVWD", *l) ? tl->v[i] * MM_PER_INCH : tl->v[i]);
    }
    printf("%s%s\n", tl->comment[0] ? "  ;" : "", tl->comment);
}

int ctl_tool_list(struct ctl *c, int json)
{
    char path[300];
    int rc = ctl_file_path(c, "tool_table", path, sizeof path);
    if (rc != CTL_OK)
        return rc;
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "cnc-ctl: tool list: %s: %s (it is on the NCK's host)\n", path,
                strerror(errno));
        return CTL_REJECTED;
    }
    char line[1024];
    int n = 0;
    if (json)
        putchar('[');
    while (fgets(line, sizeof line, f)) {
        struct tool_line tl;
        if (parse_tool(line, &tl) == 0)
            print_tool(&tl, json, n++ == 0);
    }
    fclose(f);
    if (json)
        puts("]");
    return CTL_OK;
}
