/* tools/ini-man VERSION DATE > ncpar.ini.5: the machine INI's manual page,
 * printed from the table the reader checks keys against
 * (include/ncpar/config.h). Before it prints anything it loads, through
 * the reader itself, a probe INI for each row: every value the row allows
 * (both ends of its range, each word, its example) must be taken, a value
 * just outside the range must be refused as a bad value, and the default
 * the row states must leave the machine as the key left out does. Any
 * disagreement is printed and the exit status is 1, so the build stops
 * rather than ship a page that says what the reader does not do. */
#include "ncpar/config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* A machine every probe can add one key to: the reader's required keys for
 * XYZA (A for the keys only a rotary axis takes). */
static const char *const base[][3] = {
    { "TRAJ", "COORDINATES", "XYZA" },
#define AXIS(s, lo, hi)                                                                      \
    { s, "MIN_LIMIT", lo }, { s, "MAX_LIMIT", hi }, { s, "MAX_VELOCITY", "100" },            \
        { s, "MAX_ACCELERATION", "1000" }, { s, "FERROR", "1" }
    AXIS("AXIS_X", "-500", "500"), AXIS("AXIS_Y", "-500", "500"), AXIS("AXIS_Z", "-250", "50"),
    AXIS("AXIS_A", "-360", "360"),
#undef AXIS
};
enum { N_BASE = sizeof base / sizeof base[0] };

enum verdict { TAKEN, BAD_VALUE, UNKNOWN };

static int failures;

/* pattern with its placeholder filled in: <L> -> X, <n> -> 0 */
static void instance(const char *pat, char *out, size_t len)
{
    size_t o = 0;
    for (const char *p = pat; *p && o + 1 < len;) {
        if (!strncmp(p, "<L>", 3) || !strncmp(p, "<n>", 3)) {
            out[o++] = p[1] == 'L' ? 'X' : '0';
            p += 3;
        } else {
            out[o++] = *p++;
        }
    }
    out[o] = '\0';
}

/* The base machine, with [sec] key = value among it when key is not NULL
 * (replacing the base's own value), written to a memory file; *line is the
 * probe key's line. */
static FILE *probe_file(const char *sec, const char *key, const char *value, unsigned *line)
{
    FILE *f = tmpfile();
    if (!f)
        return NULL;
    unsigned n = 0;
    int placed = key == NULL;
    const char *cur = "";
    for (int i = 0; i < N_BASE; i++) {
        if (strcmp(cur, base[i][0]) != 0) {
            if (!placed && !strcasecmp(cur, sec)) {
                fprintf(f, "%s = %s\n", key, value);
                *line = ++n;
                placed = 1;
            }
            cur = base[i][0];
            fprintf(f, "[%s]\n", cur);
            n++;
        }
        if (key && !strcasecmp(cur, sec) && !strcasecmp(base[i][1], key))
            continue;
        fprintf(f, "%s = %s\n", base[i][1], base[i][2]);
        n++;
    }
    if (!placed && !strcasecmp(cur, sec)) {
        fprintf(f, "%s = %s\n", key, value);
        *line = ++n;
        placed = 1;
    }
    if (!placed) {
        fprintf(f, "[%s]\n%s = %s\n", sec, key, value);
        *line = n + 2;
    }
    fflush(f);
    return f;
}

static int load(FILE *f, struct ncp_machine_cfg *c, struct ncp_diag *d)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fileno(f));
    ncp_machine_cfg_default(c);
    return ncp_machine_cfg_load(c, path, d);
}

/* A [CHANNEL_n] key is a channels INI's (ncp_cell_load), not a machine's:
 * probed in a channel of its own, CONFIG given unless it is the probe. */
static enum verdict probe_cell(const char *sec, const char *key, const char *value)
{
    FILE *f = tmpfile();
    if (!f) {
        perror("ini-man: tmpfile");
        exit(1);
    }
    unsigned line = 2;
    fprintf(f, "[%s]\n%s = %s\n", sec, key, value);
    if (strcasecmp(key, "CONFIG") != 0)
        fputs("CONFIG = mill.ini\n", f);
    fflush(f);
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fileno(f));
    static struct ncp_cell cell;
    struct ncp_diag d;
    int rc = ncp_cell_load(&cell, path, &d);
    fclose(f);
    if (rc == 1)
        return TAKEN;
    if (strstr(d.msg, "unknown key") || strstr(d.msg, "channels are"))
        return UNKNOWN;
    return d.line == line && strstr(d.msg, "bad value") ? BAD_VALUE : TAKEN;
}

static enum verdict probe(const char *sec, const char *key, const char *value)
{
    if (!strncasecmp(sec, "CHANNEL_", 8))
        return probe_cell(sec, key, value);
    unsigned line = 0;
    FILE *f = probe_file(sec, key, value, &line);
    if (!f) {
        perror("ini-man: tmpfile");
        exit(1);
    }
    static struct ncp_machine_cfg c;
    struct ncp_diag d;
    int rc = load(f, &c, &d);
    fclose(f);
    if (rc == NCP_OK)
        return TAKEN;
    if (strstr(d.msg, "unknown key") || strstr(d.msg, "unknown section"))
        return UNKNOWN;
    /* a check across keys (MIN_LIMIT below MAX_LIMIT, ...) is no verdict on the value */
    return d.line == line && strstr(d.msg, "bad value") ? BAD_VALUE : TAKEN;
}

static void expect(const struct ncp_ini_key *k, const char *sec, const char *key,
                   const char *value, enum verdict want)
{
    enum verdict got = probe(sec, key, value);
    if (got == want)
        return;
    static const char *const says[] = { "takes", "refuses as a bad value", "does not know" };
    fprintf(stderr, "ini-man: [%s] %s = %s: the reader %s it, the table says it %s\n",
            k->section, k->key, value, says[got], says[want]);
    failures++;
}

/* x as a file would write it: no exponent, no trailing zeros */
static void plain(char *buf, size_t len, double x)
{
    snprintf(buf, len, "%.12f", x);
    char *dot = strchr(buf, '.');
    char *e = buf + strlen(buf) - 1;
    while (dot && e > dot && *e == '0')
        *e-- = '\0';
    if (dot && e == dot)
        *e = '\0';
    if (!strcmp(buf, "-0"))
        snprintf(buf, len, "0");
}

/* The default the row states leaves the machine as the key left out does. */
static void check_default(const struct ncp_ini_key *k, const char *sec, const char *key)
{
    if (!k->def)
        return;
    char *end;
    (void)strtod(k->def, &end);
    int numeric = end != k->def && !*end;
    if (!numeric && k->kind != NCP_INI_WORD && k->kind != NCP_INI_TEXT)
        return;     /* "the axis's", "SERVO_PERIOD": another key's value */
    static struct ncp_machine_cfg without, with;
    struct ncp_diag d;
    unsigned line = 0;
    FILE *f = probe_file(sec, NULL, NULL, &line);
    FILE *g = probe_file(sec, key, k->def, &line);
    if (!f || !g || load(f, &without, &d) != NCP_OK) {
        fprintf(stderr, "ini-man: the probe machine does not load: %s\n", d.msg);
        exit(1);
    }
    int rc = load(g, &with, &d);
    /* refused for another key's sake (X_OFFSET under trivkins): no verdict */
    if (rc != NCP_OK && !strstr(d.msg, "bad value"))
        rc = NCP_OK, memcpy(&with, &without, sizeof with), d.msg[0] = '\0';
    /* both come from ncp_machine_cfg_default's memset and the same code
     * after it: their padding is alike, a difference is a member's */
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison)
    if (rc != NCP_OK || memcmp(&with, &without, sizeof with) != 0) {
        fprintf(stderr, "ini-man: [%s] %s: the default %s is not what the reader uses "
                        "when the key is left out%s%s\n", k->section, k->key, k->def,
                d.msg[0] ? ": " : "", d.msg);
        failures++;
    }
    fclose(f);
    fclose(g);
}

static void check_row(const struct ncp_ini_key *k)
{
    char sec[32], key[48], v[64];
    instance(k->probe_section ? k->probe_section : k->section, sec, sizeof sec);
    instance(k->key, key, sizeof key);
    if (probe(sec, key, k->example ? k->example : k->def ? k->def : "0") == UNKNOWN) {
        fprintf(stderr, "ini-man: [%s] %s: the reader does not know it\n", k->section, k->key);
        failures++;
        return;
    }
    double lo = k->lo, hi = k->hi;
    if (k->kind == NCP_INI_CPU)
        hi = (double)sysconf(_SC_NPROCESSORS_ONLN) - 1;
    switch (k->kind) {
    case NCP_INI_REAL: {
        double step = fmax(fmax(fabs(lo), fabs(hi)) * 1e-3, 1e-10);
        plain(v, sizeof v, lo);
        expect(k, sec, key, v, TAKEN);
        plain(v, sizeof v, hi);
        expect(k, sec, key, v, TAKEN);
        plain(v, sizeof v, lo - fmin(step, fmax(fabs(lo), 1e-9) * 0.5));
        expect(k, sec, key, v, BAD_VALUE);
        plain(v, sizeof v, hi + step);
        expect(k, sec, key, v, BAD_VALUE);
        break;
    }
    case NCP_INI_INT:
    case NCP_INI_CPU:
        plain(v, sizeof v, lo);
        expect(k, sec, key, v, TAKEN);
        plain(v, sizeof v, hi);
        expect(k, sec, key, v, TAKEN);
        plain(v, sizeof v, lo - 1);
        expect(k, sec, key, v, BAD_VALUE);
        /* above 2^53 a double has no hi + 1 */
        plain(v, sizeof v, hi + 1 > hi ? hi + 1 : hi * 2);
        expect(k, sec, key, v, BAD_VALUE);
        plain(v, sizeof v, lo + 0.5);
        expect(k, sec, key, v, BAD_VALUE);
        break;
    case NCP_INI_WORD: {
        char words[128];
        snprintf(words, sizeof words, "%s", k->values);
        char *save = NULL;
        for (char *w = strtok_r(words, "|", &save); w; w = strtok_r(NULL, "|", &save))
            expect(k, sec, key, w, TAKEN);
        expect(k, sec, key, "no-such-word", BAD_VALUE);
        break;
    }
    case NCP_INI_TEXT:
        expect(k, sec, key, k->example, TAKEN);
        break;
    }
    check_default(k, sec, key);
}

/* text for roff: backslashes doubled, '-' as the minus/hyphen escape */
static void roff(const char *s)
{
    for (; *s; s++) {
        if (*s == '\\')
            fputs("\\e", stdout);
        else if (*s == '-')
            fputs("\\-", stdout);
        else
            putchar(*s);
    }
}

static void print_values(const struct ncp_ini_key *k)
{
    char a[64], b[64];
    switch (k->kind) {
    case NCP_INI_REAL:
    case NCP_INI_INT:
        plain(a, sizeof a, k->lo);
        plain(b, sizeof b, k->hi);
        fputs(k->kind == NCP_INI_INT ? "a whole number from " : "from ", stdout);
        roff(a);
        fputs(" to ", stdout);
        roff(b);
        if (k->unit[0]) {
            putchar(' ');
            roff(k->unit);
        }
        break;
    case NCP_INI_CPU:
        fputs("a CPU number of this machine, or \\-1", stdout);
        break;
    case NCP_INI_WORD:
        for (const char *p = k->values; *p; p++) {
            if (*p == '|') {
                fputs(p[1] && !strchr(p + 1, '|') ? " or " : ", ", stdout);
                continue;
            }
            const char *e = p + strcspn(p, "|");
            fputs("\\fB", stdout);
            char w[64];
            snprintf(w, sizeof w, "%.*s", (int)(e - p), p);
            roff(w);
            fputs("\\fR", stdout);
            p = e - 1;
        }
        break;
    case NCP_INI_TEXT:
        roff(k->values);
        break;
    }
}

static void print_page(const char *version, const char *date)
{
    printf(".TH NCPAR.INI 5 \"%s\" \"ncpar %s\" \"ncpar manual\"\n", date, version);
    puts(".SH NAME\n"
         "ncpar.ini \\- machine configuration of the ncpar numerical control kernel\n"
         ".SH SYNOPSIS\n"
         ".I /etc/ncpar/MACHINE.ini\n"
         ".SH DESCRIPTION\n"
         "The machine INI, in LinuxCNC's style, tells\n"
         ".BR cnc\\-run (1)\n"
         "(\\fBrun\\fR and \\fBserve \\-\\-config\\fR),\n"
         ".BR cnc\\-axis (1)\n"
         "and\n"
         ".BR cnc\\-drive\\-sim (1)\n"
         "what machine they drive.\n"
         "Lines are \\fBKEY = VALUE\\fR under a \\fB[SECTION]\\fR; \\fB#\\fR and \\fB;\\fR\n"
         "start a comment. Names are read in any case.\n"
         ".PP\n"
         "Every key is known: a section or key not listed here, a key or section given\n"
         "twice, or a value outside its range is an error that names the file, the line,\n"
         "the section and the key, and the program exits with status 1 before anything\n"
         "moves. A typo in a machine file never falls back to a default silently.\n"
         "Numbers are plain decimals (an exponent is allowed, no units, no hex).\n"
         ".PP\n"
         "A key left out takes its default; a key without one is required where its\n"
         "section says so, else optional. This page is generated from the table the\n"
         "reader checks every key against.\n"
         ".SH SECTIONS AND KEYS");
    for (size_t s = 0; s < ncp_ini_n_sections; s++) {
        const struct ncp_ini_section *sec = &ncp_ini_sections[s];
        fputs(".SS [", stdout);
        roff(sec->name);
        fputs("]\n", stdout);
        fputs("\\&", stdout);   /* a text line may start with '.' */
        roff(sec->doc);
        putchar('\n');
        for (size_t i = 0; i < ncp_ini_n_keys; i++) {
            const struct ncp_ini_key *k = &ncp_ini_keys[i];
            if (strcmp(k->section, sec->name) != 0)
                continue;
            fputs(".TP\n\\fB", stdout);
            roff(k->key);
            fputs("\\fR = ", stdout);
            print_values(k);
            if (k->def) {
                fputs("; default \\fB", stdout);
                roff(k->def);
                fputs("\\fR", stdout);
            }
            fputs("\n\\&", stdout);
            roff(k->doc);
            putchar('\n');
        }
    }
    puts(".SH FILES\n"
         ".TP\n"
         ".I /etc/ncpar/*.ini\n"
         "The machines the service runs: \\fBncpar@MACHINE.service\\fR reads\n"
         ".IR /etc/ncpar/MACHINE.ini .\n"
         ".TP\n"
         ".I /usr/share/ncpar/rt\\-config/\n"
         "Example machines (sim\\-3axis.ini, sim\\-home.ini, xyzac\\-trt.ini, can\\-3axis.ini, ...)\n"
         "and the interpreter's thread maps.\n"
         ".SH SEE ALSO\n"
         ".BR cnc\\-run (1),\n"
         ".BR cnc\\-ctl (1),\n"
         ".BR cnc\\-axis (1),\n"
         ".BR cnc\\-drive\\-sim (1)");
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fputs("usage: ini-man VERSION DATE > ncpar.ini.5\n", stderr);
        return 1;
    }
    for (size_t i = 0; i < ncp_ini_n_keys; i++)
        check_row(&ncp_ini_keys[i]);
    for (size_t i = 0; i < ncp_ini_n_keys; i++) {
        int listed = 0;
        for (size_t s = 0; s < ncp_ini_n_sections; s++)
            listed |= !strcmp(ncp_ini_keys[i].section, ncp_ini_sections[s].name);
        if (!listed) {
            fprintf(stderr, "ini-man: [%s] has no section entry\n", ncp_ini_keys[i].section);
            failures++;
        }
    }
    if (failures) {
        fprintf(stderr, "ini-man: %d disagreement%s between the table "
                        "(src/config/ini_keys.c) and the reader\n",
                failures, failures == 1 ? "" : "s");
        return 1;
    }
    print_page(argv[1], argv[2]);
    return ferror(stdout) ? 1 : 0;
}
