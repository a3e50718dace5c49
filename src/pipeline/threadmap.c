/* Thread maps: built-in defaults per mode, and INI files (see rt-config). */
#include "ncpar/pipeline.h"
#include "ncpar/num.h"

#include <errno.h>
#include <ini.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#define DEFAULT_STRING_ROWS 32 /* of n chunks of ~4 KB: 128 KB of text per lexer ahead */
/* Deep rings: with more threads than cores every stage has to sleep now and
 * then, and a wake-up is paid per half ring: shallow rings (64/128 slots)
 * spend a 2-core run in futex calls and context switches. */
#define DEFAULT_PARSED_ROWS 1024
/* A command slot is 4 KB and the ring is prefaulted before the start: 256 of
 * them keep the start-up of a short program to a few milliseconds. */
#define DEFAULT_CMD_SLOTS 256
#define DEFAULT_START_TIMEOUT_US 1000
/* A chunk of 32 KB of CAM text (about a thousand blocks) is fine enough to
 * balance the two threads, and the helper may run up to 8 chunks ahead,
 * which rides out the analyzer's and its own uneven spells; smaller chunks
 * leave the analyzer lexing more of the blocks itself and the two threads'
 * CPU time further apart (bench/RESULTS.md compares the sizes). */
#define DEFAULT_LEX_AHEAD_BYTES 32768
#define MAX_LEX_AHEAD_BYTES (1 << 20)
#define MAX_ROWS (1 << 20)
#define MAX_START_TIMEOUT_US 10000000

static int clamp(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static struct ncp_rt_place spec_on(int cpu)
{
    struct ncp_rt_place s = { cpu, SCHED_OTHER, 0 };
    return s;
}

void ncp_thread_map_default(struct ncp_thread_map *m, enum ncp_thread_mode mode,
                            int n_lexers, int n_executors)
{
    memset(m, 0, sizeof *m);
    m->mode = mode;
    m->n_lexers = clamp(n_lexers, 0, NCP_MAX_LEXERS);
    m->n_executors = clamp(n_executors, 0, NCP_MAX_EXECUTORS);
    m->string_rows = DEFAULT_STRING_ROWS;
    m->parsed_rows = DEFAULT_PARSED_ROWS;
    m->cmd_slots = DEFAULT_CMD_SLOTS;
    m->start_timeout_us = DEFAULT_START_TIMEOUT_US;
    m->lex_ahead_bytes = DEFAULT_LEX_AHEAD_BYTES;

    /* ATT: the feeder alone on CPU0 as in the paper's tables, then lexers,
     * analyzer and executors round-robin in data-flow order from CPU1 on, the
     * output on the analyzer's CPU; others: the OS. */
    int ncpu = 1;
    if (mode == NCP_MODE_ATT) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        ncpu = n > 0 ? (int)(n > CPU_SETSIZE ? CPU_SETSIZE : n) : 1;
    }
    int next = 1;
#define PLACE() (mode == NCP_MODE_ATT ? (next++) % ncpu : -1)
    m->feeder = spec_on(mode == NCP_MODE_ATT ? 0 : -1);
    for (int i = 0; i < NCP_MAX_LEXERS; i++)
        m->lexer[i] = spec_on(i < m->n_lexers ? PLACE() : -1);
    m->analyzer = spec_on(PLACE());
    for (int i = 0; i < NCP_MAX_EXECUTORS; i++)
        m->executor[i] = spec_on(i < m->n_executors ? PLACE() : -1);
    /* With executor threads the output sits beside the analyzer: command
     * slots crossing from one to the other cost the analyzer more than its
     * own work (bench/RESULTS.md, ATT placements). Without them the output
     * formats packed commands, a third of the work, and takes the next CPU
     * (on two CPUs: the lexer's, which has time to spare). */
    m->output = m->n_executors > 0 ? m->analyzer : spec_on(PLACE());
#undef PLACE
}

/* ---- INI loading ---------------------------------------------------------- */

enum spec_key { KEY_CPU = 1, KEY_POLICY = 2, KEY_PRIORITY = 4 };

/* What the file said, applied over the defaults once mode and counts are known. */
struct loaded_spec {
    struct ncp_rt_place v;
    unsigned set;       /* enum spec_key bits */
    int line;           /* first line of its section, for late checks */
};

struct map_loader {
    FILE *f;
    int line;           /* lines read so far (the handler's key is on this one) */
    int section_line;   /* line of the last [section] header */
    struct ncp_diag *d;
    int failed;
    /* [pipeline] */
    int mode, lexers, executors, string_rows, parsed_rows, cmd_slots, timeout, inline_out;
    int lex_ahead;
    int inline_line;    /* where inline_output was set */
    unsigned pipe_set;
    struct loaded_spec feeder, analyzer, output;
    struct loaded_spec lexer[NCP_MAX_LEXERS], executor[NCP_MAX_EXECUTORS];
    /* keys given so far: a second one would silently win */
    struct { char section[24], key[24]; int line; } seen[128];
    int n_seen;
};

__attribute__((format(printf, 3, 4)))
static int fail(struct map_loader *L, int line, const char *fmt, ...)
{
    char msg[NCP_DIAG_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    /* clang-analyzer loses track of va_start when it analyses several files in
     * one run and then calls ap uninitialised: a false positive. */
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (!L->failed) {
        L->failed = 1;
        ncp_diag_set(L->d, NCP_ERR_IO, (uint32_t)line, 0, "%s", msg);
    }
    return 0;
}

static const char *const pipe_keys[] = { "mode", "lexers", "executors", "string_rows",
                                         "parsed_rows", "cmd_slots", "start_timeout_us",
                                         "inline_output", "lex_ahead_bytes" };

static int pipeline_key(struct map_loader *L, const char *name, const char *value)
{
    size_t k = 0;
    while (k < sizeof pipe_keys / sizeof *pipe_keys && strcmp(name, pipe_keys[k]) != 0)
        k++;
    if (k == sizeof pipe_keys / sizeof *pipe_keys)
        return fail(L, L->line, "unknown key '%s' in [%s]", name, "pipeline");
    int ok = 0;
    switch (k) {
    case 0:
        {
            enum ncp_thread_mode mode;
            ok = ncp_thread_mode_parse(value, &mode) == 0;
            if (ok)
                L->mode = (int)mode;
        }
        if (!ok)
            return fail(L, L->line, "bad value '%s' for %s (serial, det or att)", value,
                        name);
        break;
    case 1:
        if (ncp_num_int(value, 0, NCP_MAX_LEXERS, &L->lexers))
            return fail(L, L->line, "bad value '%s' for %s (0 to 16; 0: the analyzer lexes)",
                        value, name);
        break;
    case 2:
        if (ncp_num_int(value, 0, NCP_MAX_EXECUTORS, &L->executors))
            return fail(L, L->line, "bad value '%s' for %s (0 to 16; 0: the output thread executes)",
                        value, name);
        break;
    case 3:
    case 4:
    case 5: {
        int *dst = k == 3 ? &L->string_rows : k == 4 ? &L->parsed_rows : &L->cmd_slots;
        if (ncp_num_int(value, 1, MAX_ROWS, dst))
            return fail(L, L->line, "bad value '%s' for %s (1 to 1048576)", value, name);
        break;
    }
    case 8:
        if (ncp_num_int(value, 0, MAX_LEX_AHEAD_BYTES, &L->lex_ahead))
            return fail(L, L->line, "bad value '%s' for %s (0 to %d; 0: the output thread never lexes)",
                        value, name, MAX_LEX_AHEAD_BYTES);
        break;
    case 7:
        if (ncp_num_int(value, 0, 1, &L->inline_out))
            return fail(L, L->line, "bad value '%s' for %s (0 or 1)", value, name);
        L->inline_line = L->line;
        break;
    default:
        if (ncp_num_int(value, 0, MAX_START_TIMEOUT_US, &L->timeout))
            return fail(L, L->line, "bad value '%s' for %s (0 to 10000000)", value, name);
        break;
    }
    L->pipe_set |= 1u << k;
    return 1;
}

static int spec_key(struct map_loader *L, struct loaded_spec *s, const char *section,
                    const char *name, const char *value)
{
    if (!s->line)
        s->line = L->section_line;
    if (!strcmp(name, "cpu")) {
        if (ncp_num_int(value, -1, CPU_SETSIZE - 1, &s->v.cpu))
            return fail(L, L->line, "bad value '%s' for cpu (-1 = any, or a CPU number)",
                        value);
        s->set |= KEY_CPU;
    } else if (!strcmp(name, "policy")) {
        if (!strcasecmp(value, "SCHED_OTHER") || !strcasecmp(value, "other"))
            s->v.policy = SCHED_OTHER;
        else if (!strcasecmp(value, "SCHED_FIFO") || !strcasecmp(value, "fifo"))
            s->v.policy = SCHED_FIFO;
        else
            return fail(L, L->line, "bad value '%s' for %s (SCHED_OTHER or SCHED_FIFO)",
                        value, name);
        s->set |= KEY_POLICY;
    } else if (!strcmp(name, "priority")) {
        if (ncp_num_int(value, 0, 99, &s->v.priority))
            return fail(L, L->line, "bad value '%s' for %s (0 to 99)", value, name);
        s->set |= KEY_PRIORITY;
    } else {
        return fail(L, L->line, "unknown key '%s' in [%s]", name, section);
    }
    return 1;
}

/* [lexer.N] / [executor.N] -> N, or -1. */
static int section_index(const char *section, const char *prefix, int max)
{
    size_t n = strlen(prefix);
    int idx;
    if (strncmp(section, prefix, n) != 0 || section[n] != '.')
        return -1;
    if (ncp_num_int(section + n + 1, 0, max - 1, &idx))
        return -1;
    return idx;
}

static struct loaded_spec *spec_section(struct map_loader *L, const char *section)
{
    if (!strcmp(section, "feeder"))
        return &L->feeder;
    if (!strcmp(section, "analyzer"))
        return &L->analyzer;
    if (!strcmp(section, "output"))
        return &L->output;
    int i = section_index(section, "lexer", NCP_MAX_LEXERS);
    if (i >= 0)
        return &L->lexer[i];
    i = section_index(section, "executor", NCP_MAX_EXECUTORS);
    if (i >= 0)
        return &L->executor[i];
    return NULL;
}

static int known_section(struct map_loader *L, const char *section)
{
    return !strcmp(section, "pipeline") || spec_section(L, section) != NULL;
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    struct map_loader *L = user;
    if (L->failed)
        return 0;
    for (int i = 0; i < L->n_seen; i++)
        if (!strcmp(L->seen[i].section, section) && !strcmp(L->seen[i].key, name))
            return fail(L, L->line, "[%s] %s given twice (first on line %d); each key once",
                        section, name, L->seen[i].line);
    /* known keys are fewer than the slots: an unknown one stops the load */
    if (L->n_seen < (int)(sizeof L->seen / sizeof L->seen[0])) {
        snprintf(L->seen[L->n_seen].section, sizeof L->seen[0].section, "%s", section);
        snprintf(L->seen[L->n_seen].key, sizeof L->seen[0].key, "%s", name);
        L->seen[L->n_seen++].line = L->line;
    }
    if (!strcmp(section, "pipeline"))
        return pipeline_key(L, name, value);
    struct loaded_spec *s = spec_section(L, section);
    if (!s) {
        if (!*section)
            return fail(L, L->line, "key '%s' outside of a section", name);
        return fail(L, L->line, "unknown section [%s] (key '%s')", section, name);
    }
    return spec_key(L, s, section, name, value);
}

/* inih hands over one line per call: counting them here gives the handler its
 * line, and section headers are checked even when no key follows them. */
static char *read_line(char *str, int num, void *stream)
{
    struct map_loader *L = stream;
    char *s = fgets(str, num, L->f);
    if (!s)
        return NULL;
    L->line++;
    const char *p = s;
    while (*p == ' ' || *p == '\t')
        p++;
    if (*p == '[')
        L->section_line = L->line;
    if (*p == '[' && !L->failed) {
        const char *close = strchr(p, ']');
        char name[64];
        size_t len = close ? (size_t)(close - p - 1) : 0;
        if (close && len < sizeof name) {
            memcpy(name, p + 1, len);
            name[len] = '\0';
            if (!known_section(L, name))
                fail(L, L->line, "unknown section [%s]", name);
        }
    }
    return s;
}

static void apply(struct ncp_rt_place *dst, const struct loaded_spec *s)
{
    if (s->set & KEY_CPU)
        dst->cpu = s->v.cpu;
    if (s->set & KEY_POLICY)
        dst->policy = s->v.policy;
    if (s->set & KEY_PRIORITY)
        dst->priority = s->v.priority;
}

static int check_spec(struct map_loader *L, const struct ncp_rt_place *t,
                      const struct loaded_spec *s, const char *what)
{
    if (t->policy == SCHED_FIFO && (t->priority < 1 || t->priority > 99))
        return fail(L, s->line, "%s: SCHED_FIFO needs a priority from 1 to 99", what);
    return 1;
}

/* Checks that need the whole file: sections beyond the thread counts, FIFO
 * without a priority. */
static void finish(struct map_loader *L, struct ncp_thread_map *m)
{
    ncp_thread_map_default(m, (enum ncp_thread_mode)L->mode, L->lexers, L->executors);
    if (L->pipe_set & (1u << 3))
        m->string_rows = L->string_rows;
    if (L->pipe_set & (1u << 4))
        m->parsed_rows = L->parsed_rows;
    if (L->pipe_set & (1u << 5))
        m->cmd_slots = L->cmd_slots;
    if (L->pipe_set & (1u << 6))
        m->start_timeout_us = L->timeout;
    if (L->pipe_set & (1u << 8))
        m->lex_ahead_bytes = L->lex_ahead;
    if (L->inline_out && m->n_executors > 0)
        fail(L, L->inline_line, "inline_output = 1 needs executors = 0 (the analyzer then executes)");
    m->inline_output = L->inline_out;
    if (L->inline_out && L->output.set)
        fail(L, L->output.line, "[output] but inline_output = 1: the analyzer writes the output");
    char what[32];
    apply(&m->feeder, &L->feeder);
    check_spec(L, &m->feeder, &L->feeder, "[feeder]");
    apply(&m->analyzer, &L->analyzer);
    check_spec(L, &m->analyzer, &L->analyzer, "[analyzer]");
    apply(&m->output, &L->output);
    check_spec(L, &m->output, &L->output, "[output]");
    for (int i = 0; i < NCP_MAX_LEXERS; i++) {
        if (!L->lexer[i].set)
            continue;
        snprintf(what, sizeof what, "[lexer.%d]", i);
        if (i >= m->n_lexers)
            fail(L, L->lexer[i].line, "%s but the map has %d lexers", what, m->n_lexers);
        apply(&m->lexer[i], &L->lexer[i]);
        check_spec(L, &m->lexer[i], &L->lexer[i], what);
    }
    for (int i = 0; i < NCP_MAX_EXECUTORS; i++) {
        if (!L->executor[i].set)
            continue;
        snprintf(what, sizeof what, "[executor.%d]", i);
        if (i >= m->n_executors)
            fail(L, L->executor[i].line, "%s but the map has %d executors", what,
                 m->n_executors);
        apply(&m->executor[i], &L->executor[i]);
        check_spec(L, &m->executor[i], &L->executor[i], what);
    }
}

int ncp_thread_map_load(struct ncp_thread_map *m, const char *path, struct ncp_diag *d)
{
    memset(d, 0, sizeof *d);
    struct map_loader *L = calloc(1, sizeof *L);
    if (!L)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
    L->d = d;
    L->mode = NCP_MODE_DET;
    L->lexers = 2;
    L->executors = 1;
    L->f = fopen(path, "r");
    int rc = NCP_OK;
    if (!L->f) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot open thread map: %s",
                          strerror(errno));
        goto done;
    }
    struct stat st;
    memset(&st, 0, sizeof st);
    if (fstat(fileno(L->f), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "thread map: %s",
                          S_ISDIR(st.st_mode) ? "a directory, not a file"
                                              : "not a regular, non-empty file");
        goto done;
    }
    int bad = ini_parse_stream(read_line, L, on_key, L);
    if (bad > 0 && !L->failed)
        fail(L, bad, "expected 'key = value' or '[section]'");
    else if (bad < 0 && !L->failed)
        fail(L, 0, "cannot read thread map");
    if (!L->failed)
        finish(L, m);
    rc = L->failed ? d->code : NCP_OK;
done:
    if (L->f)
        fclose(L->f);
    free(L);
    return rc;
}

static const char *const mode_names[] = {
    [NCP_MODE_SERIAL] = "serial", [NCP_MODE_DET] = "det", [NCP_MODE_ATT] = "att"
};

int ncp_thread_mode_parse(const char *name, enum ncp_thread_mode *mode)
{
    for (int m = NCP_MODE_SERIAL; m <= NCP_MODE_ATT; m++) {
        if (!strcasecmp(name, mode_names[m])) {
            *mode = (enum ncp_thread_mode)m;
            return 0;
        }
    }
    return -1;
}

const char *ncp_thread_mode_name(enum ncp_thread_mode m)
{
    return (unsigned)m <= NCP_MODE_ATT ? mode_names[m] : "?";
}
