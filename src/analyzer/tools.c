/* Tool table (LinuxCNC .tbl format), T selection, M6 and M61. Entries keep
 * rs274's indexing: 0 is the spindle, 1..n the table lines in file order, and
 * offsets stay in the table's unit (inch), converted when used. */
#include "floor.h"
#include "stages.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* What rs274 loads when started without -t (LinuxCNC's sample tool.tbl). */
static const char ncp_default_table[] =
    "T1 P1 D0.125000 Z+0.511000\n"
    "T2 P2 D0.062500 Z+0.100000\n"
    "T3 P3 D0.201000 Z+1.273000\n"
    "T99999 P123 Z+0.100000\n";

static void ncp_tool_field(struct ncp_tool_entry *t, double *more, int *toolno, char c, double v)
{
    switch (c) {
    case 'T': *toolno = ncp_trunc_int(v); break;
    case 'P': t->pocket = ncp_trunc_int(v); break;
    case 'X': t->x_offset = v; break;
    case 'Y': more[0] = v; break;
    case 'Z': t->z_offset = v; break;
    case 'A': more[1] = v; break;
    case 'B': more[2] = v; break;
    case 'C': more[3] = v; break;
    case 'U': more[4] = v; break;
    case 'V': more[5] = v; break;
    case 'W': more[6] = v; break;
    case 'D': t->diameter = v; break;
    case 'I': t->frontangle = v; break;
    case 'J': t->backangle = v; break;
    case 'Q': t->orientation = ncp_trunc_int(v); break;
    default: break;
    }
}

/* One line "T1 P1 Z0.5 D0.25 ;comment" -> entry; 0 if the line has no T. */
static int ncp_tool_line(const char *s, const char *end, struct ncp_tool_entry *t, double *more,
                         int *toolno)
{
    memset(t, 0, sizeof *t);
    memset(more, 0, 7 * sizeof *more);
    *toolno = -1;
    while (s < end && *s != ';') {
        char c = (char)(*s >= 'a' && *s <= 'z' ? *s - 32 : *s);
        if (c >= 'A' && c <= 'Z') {
            char buf[64];
            size_t n = 0;
            s++;
            while (s < end && n < sizeof buf - 1 &&
                   (strchr("+-.0123456789eE", *s) != NULL))
                buf[n++] = *s++;
            buf[n] = '\0';
            ncp_tool_field(t, more, toolno, c, strtod(buf, NULL));
        } else {
            s++;
        }
    }
    return *toolno >= 0;
}

/* What the loader skips in silence, as rs274 does ("Unrecognized line
 * skipped"): a word that is no tool table letter with a number, or a line
 * without a tool number. Returns 1 for a tool line, 0 for a blank or comment
 * line, -1 (why filled) for a line the loader skips. */
static int ncp_tool_line_check(const char *s, const char *end, char *why, size_t len)
{
    int has_t = 0, words = 0;
    while (s < end && *s != ';') {
        unsigned char c = (unsigned char)*s;
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
            s++;
            continue;
        }
        char up = (char)(c >= 'a' && c <= 'z' ? c - 32 : c);
        if (!(up >= 'A' && up <= 'Z')) {
            if (c >= 0x20 && c < 0x7f)
                snprintf(why, len, "unexpected '%c'", c);
            else
                snprintf(why, len, "unexpected byte 0x%02x", c);
            return -1;
        }
        if (!strchr("TPXYZABCUVWDIJQ", up)) {
            snprintf(why, len, "unknown word '%c'", c);
            return -1;
        }
        const char *num = ++s;
        while (s < end && strchr("+-.0123456789eE", *s) != NULL && *s)
            s++;
        char buf[64], *stop;
        size_t n = (size_t)(s - num);
        if (n == 0 || n >= sizeof buf) {
            snprintf(why, len, "'%c' without a number", c);
            return -1;
        }
        memcpy(buf, num, n);
        buf[n] = '\0';
        double v = strtod(buf, &stop);
        if (*stop || !isfinite(v)) {
            snprintf(why, len, "'%c' with a bad number '%s'", c, buf);
            return -1;
        }
        words++;
        if (up == 'T') {
            if (v < 0) {
                snprintf(why, len, "negative tool number");
                return -1;
            }
            has_t = 1;
        }
    }
    if (words && !has_t) {
        snprintf(why, len, "no T word (tool number)");
        return -1;
    }
    return words > 0;
}

int ncp_tool_table_check(const char *path, FILE *warn, struct ncp_diag *d)
{
    enum { SHOWN_MAX = 20 }; /* random bytes make hundreds of lines */
    FILE *f = fopen(path, "rb");
    struct stat st;
    if (!f || fstat(fileno(f), &st) != 0) {
        int e = errno;
        if (f)
            fclose(f);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read tool table %s: %s", path,
                            strerror(e));
    }
    if (S_ISDIR(st.st_mode)) {
        fclose(f);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read tool table %s: %s", path,
                            strerror(EISDIR));
    }
    char line[4096];
    unsigned no = 0, bad = 0;
    int partial = 0;
    while (fgets(line, sizeof line, f)) {
        size_t n = strlen(line);
        int whole = n && line[n - 1] == '\n';
        if (!partial)
            no++;
        /* the rest of an overlong line was judged with its start */
        if (partial) {
            partial = !whole;
            continue;
        }
        partial = !whole;
        char why[64];
        if (ncp_tool_line_check(line, line + n, why, sizeof why) >= 0)
            continue;
        if (++bad <= SHOWN_MAX && warn)
            fprintf(warn, "%s:%u: warning: tool table line skipped: %s\n", path, no, why);
    }
    int err = ferror(f) ? errno : 0;
    fclose(f);
    if (err)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read tool table %s: %s", path,
                            strerror(err));
    if (bad > SHOWN_MAX && warn)
        fprintf(warn, "%s: warning: %u more tool table lines skipped\n", path, bad - SHOWN_MAX);
    return NCP_OK;
}

int ncp_tools_read_line(const char *s, const char *end, struct ncp_tool_entry *t, double *more,
                        int *toolno)
{
    char why[64];
    return ncp_tool_line_check(s, end, why, sizeof why) > 0 && ncp_tool_line(s, end, t, more, toolno);
}

static void ncp_tools_parse(struct ncp_analyzer *a, const char *text, size_t len)
{
    const char *p = text, *end = text + len;
    a->n_tools = 1;
    memset(&a->tools[0], 0, sizeof a->tools[0]);
    a->tools[0].pocket = -1; /* the empty spindle's, as rs274 reports it */
    a->tool_no[0] = 0;
    memset(a->tool_more[0], 0, sizeof a->tool_more[0]);
    while (p < end && a->n_tools < NCP_MAX_TOOLS) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        int no;
        if (ncp_tools_read_line(p, le, &a->tools[a->n_tools], a->tool_more[a->n_tools], &no))
            a->tool_no[a->n_tools++] = no;
        p = nl ? nl + 1 : end;
    }
}

char *ncp_tools_read_file(const char *path, size_t *len, struct ncp_diag *d)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot open tool table %s: %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16;
    *len = 0;
    char *buf = malloc(cap);
    while (buf) {
        *len += fread(buf + *len, 1, cap - *len, f);
        if (*len < cap)
            break;
        char *nb = realloc(buf, cap * 2);
        if (!nb)
            free(buf);
        buf = nb;
        cap *= 2;
    }
    int bad = ferror(f);
    fclose(f);
    if (!buf || bad) {
        free(buf);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read tool table %s", path);
        return NULL;
    }
    return buf;
}

int ncp_tools_load(struct ncp_analyzer *a, const char *path, struct ncp_diag *d)
{
    if (!path) {
        ncp_tools_parse(a, ncp_default_table, sizeof ncp_default_table - 1);
        return NCP_OK;
    }
    size_t len;
    char *buf = ncp_tools_read_file(path, &len, d);
    if (!buf)
        return d->code;
    ncp_tools_parse(a, buf, len);
    free(buf);
    return NCP_OK;
}

/* Index of tool number `tool` (0 = the spindle entry), -1 when not in the table. */
int ncp_tools_find(const struct ncp_analyzer *a, int tool)
{
    if (tool == 0)
        return 0;
    for (int k = 1; k < a->n_tools; k++)
        if (a->tool_no[k] == tool)
            return k;
    return -1;
}

int ncp_tools_select(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int t = ncp_trunc_int_round(w->v[NCP_LETTER('T')]);
    int idx = ncp_tools_find(a, t);
    if (idx < 0)
        return ncp_an_error(a, w->col[NCP_LETTER('T')],
                            "Requested tool %d not found in the tool table", t);
    struct ncp_canon *c = ncp_an_emit(a, NCP_C_SELECT_TOOL);
    c->tool.tool = c->tool.number = t;
    a->st.selected_pocket = idx;
    a->st.selected_pocket_no = a->tools[idx].pocket; /* T0: the spindle's */
    a->st.selected_tool = t;
    return NCP_OK;
}

static int ncp_tools_m61(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    uint16_t col = w->mcol[NCP_MG_TOOL];
    int t = NCP_HAS(w, 'Q') ? ncp_trunc_int_round(w->v[NCP_LETTER('Q')]) : -1;
    if (t < 0)
        return ncp_an_error(a, col, "Need non-negative Q-word to specify tool number with M61");
    int idx = ncp_tools_find(a, t);
    if (idx < 0)
        return ncp_an_error(a, col, "Requested tool %d not found in the tool table", t);
    a->st.current_pocket = idx;
    a->st.current_pocket_no = a->tools[idx].pocket;
    a->st.current_tool = t;
    a->st.toolchange_flag = 1;
    struct ncp_canon *c = ncp_an_emit(a, NCP_C_CHANGE_TOOL_NUMBER);
    c->tool.tool = idx;
    c->tool.number = t;
    return NCP_OK;
}

int ncp_tools_change(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    if (a->remaps) /* rs274 notes every built-in M6/M61 for the remap's epilog */
        ncp_remap_note_builtin(a);
    if (a->w.m[NCP_MG_TOOL] == NCP_M61)
        return ncp_tools_m61(a);
    /* No "Txx missing" check: rs274 starts with tool 0 selected, so an M6
     * before any T empties the spindle as T0 M6 does. */
    if (s->m.comp_side != 0)
        return ncp_an_error(a, a->w.mcol[NCP_MG_TOOL],
                            "Cannot change tools with cutter radius compensation on");
    ncp_an_emit(a, NCP_C_START_CHANGE);
    ncp_an_emit(a, NCP_C_STOP_SPINDLE_TURNING);
    s->m.spindle_dir = 0;
    struct ncp_canon *c = ncp_an_emit(a, NCP_C_CHANGE_TOOL);
    c->tool.tool = s->selected_pocket;
    c->tool.number = s->selected_tool;
    if (s->selected_pocket > 0)
        ncp_tools_copy(a, 0, s->selected_pocket);
    s->current_pocket = s->selected_pocket;
    s->current_pocket_no = s->selected_pocket_no;
    s->current_tool = s->selected_tool;
    s->toolchange_flag = 1;
    a->sai.change_flag = 1;   /* a queue buster on a machine (the change position move) */
    return NCP_OK;
}

/* #5400..#5413 mirror the spindle's entry (index 0): rs274 refreshes them
 * after a tool change and on G10 L1/L10/L11; `when_empty` zeroes them when
 * the spindle holds no tool, as the refresh after a tool change does. */
void ncp_tools_sync_params(struct ncp_analyzer *a, int when_empty)
{
    const struct ncp_tool_entry *t = &a->tools[0];
    double v[13];
    for (int ax = 0; ax < NCP_NAX; ax++)
        v[ax] = ncp_tool_offset(a, 0, ax);
    v[9] = t->diameter;
    v[10] = t->frontangle;
    v[11] = t->backangle;
    v[12] = t->orientation;
    int none = when_empty && a->tool_no[0] <= 0;
    double *no = ncp_params_slot(a->params, 5400);
    if (no)
        *no = a->tool_no[0] > 0 ? a->tool_no[0] : 0;
    for (int k = 0; k < 13; k++) {
        double *p = ncp_params_slot(a->params, 5401 + k);
        if (p)
            *p = none ? 0.0 : v[k];
    }
}

/* An entry's offset along axis `ax` (user unit): X and Z live in the public
 * entry, the other axes beside it. */
double ncp_tool_offset(const struct ncp_analyzer *a, int idx, int ax)
{
    if (ax == NCP_X)
        return a->tools[idx].x_offset;
    if (ax == NCP_Z)
        return a->tools[idx].z_offset;
    return a->tool_more[idx][ax == NCP_Y ? 0 : ax - 2];
}

void ncp_tool_set_offset(struct ncp_analyzer *a, int idx, int ax, double user)
{
    if (ax == NCP_X)
        a->tools[idx].x_offset = user;
    else if (ax == NCP_Z)
        a->tools[idx].z_offset = user;
    else
        a->tool_more[idx][ax == NCP_Y ? 0 : ax - 2] = user;
}

void ncp_tools_copy(struct ncp_analyzer *a, int dst, int src)
{
    a->tools[dst] = a->tools[src];
    a->tool_no[dst] = a->tool_no[src];
    memcpy(a->tool_more[dst], a->tool_more[src], sizeof a->tool_more[dst]);
}
