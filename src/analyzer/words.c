/* A block's words -> evaluated values, a letter bitmask and G/M codes sorted
 * into their modal groups; parameter assignments with pre-block values. */
#include "floor.h"
#include "stages.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

const char ncp_axis_letter[NCP_NAX] = {'X', 'Y', 'Z', 'A', 'B', 'C', 'U', 'V', 'W'};
const unsigned char ncp_axis_slot[NCP_NAX] = {
    NCP_LETTER('X'), NCP_LETTER('Y'), NCP_LETTER('Z'), NCP_LETTER('A'), NCP_LETTER('B'),
    NCP_LETTER('C'), NCP_LETTER('U'), NCP_LETTER('V'), NCP_LETTER('W'),
};

int ncp_axis_word(const struct ncp_words *w, int ax, double *v)
{
    int l = ncp_axis_slot[ax];
    if (!((w->has >> l) & 1u))
        return 0;
    *v = w->v[l];
    return 1;
}

/* G code (x10) -> modal group; -1 unknown. Built once (ncp_words_init). */
static int8_t ncp_g_group[1000];
static pthread_once_t ncp_g_group_once = PTHREAD_ONCE_INIT;

static void ncp_g_table_init(void)
{
    static const struct { int16_t code; int8_t group; } tab[] = {
        {NCP_G4, NCP_GG_NONMODAL}, {NCP_G10, NCP_GG_NONMODAL}, {NCP_G28, NCP_GG_NONMODAL},
        {NCP_G28_1, NCP_GG_NONMODAL}, {NCP_G30, NCP_GG_NONMODAL}, {NCP_G30_1, NCP_GG_NONMODAL},
        {NCP_G52, NCP_GG_NONMODAL}, {NCP_G53, NCP_GG_NONMODAL}, {NCP_G92, NCP_GG_NONMODAL},
        {NCP_G92_1, NCP_GG_NONMODAL}, {NCP_G92_2, NCP_GG_NONMODAL},
        {NCP_G92_3, NCP_GG_NONMODAL},
        {NCP_G5_3, NCP_GG_NONMODAL}, /* G5.3: draw the G5.2 points */
        {NCP_G0, NCP_GG_MOTION}, {NCP_G1, NCP_GG_MOTION}, {NCP_G2, NCP_GG_MOTION},
        {NCP_G3, NCP_GG_MOTION}, {NCP_G38_2, NCP_GG_MOTION}, {NCP_G38_3, NCP_GG_MOTION},
        {NCP_G38_4, NCP_GG_MOTION}, {NCP_G38_5, NCP_GG_MOTION}, {NCP_G73, NCP_GG_MOTION},
        {NCP_G74, NCP_GG_MOTION}, {NCP_G80, NCP_GG_MOTION}, {NCP_G81, NCP_GG_MOTION},
        {NCP_G82, NCP_GG_MOTION}, {NCP_G83, NCP_GG_MOTION}, {NCP_G84, NCP_GG_MOTION},
        {NCP_G85, NCP_GG_MOTION}, {NCP_G86, NCP_GG_MOTION}, {NCP_G87, NCP_GG_MOTION},
        {NCP_G88, NCP_GG_MOTION}, {NCP_G89, NCP_GG_MOTION}, {NCP_G33, NCP_GG_MOTION},
        {NCP_G33_1, NCP_GG_MOTION}, {NCP_G76, NCP_GG_MOTION}, {NCP_G5, NCP_GG_MOTION},
        {NCP_G5_1, NCP_GG_MOTION}, {NCP_G5_2, NCP_GG_MOTION},
        /* lathe profile cycles (g7x.c) */
        {NCP_G70, NCP_GG_MOTION}, {NCP_G71, NCP_GG_MOTION}, {NCP_G71_1, NCP_GG_MOTION},
        {NCP_G71_2, NCP_GG_MOTION}, {NCP_G72, NCP_GG_MOTION}, {NCP_G72_1, NCP_GG_MOTION},
        {NCP_G72_2, NCP_GG_MOTION},
        {NCP_G17, NCP_GG_PLANE}, {NCP_G18, NCP_GG_PLANE}, {NCP_G19, NCP_GG_PLANE},
        {NCP_G17_1, NCP_GG_PLANE}, {NCP_G18_1, NCP_GG_PLANE}, {NCP_G19_1, NCP_GG_PLANE},
        {NCP_G90, NCP_GG_DIST}, {NCP_G91, NCP_GG_DIST}, {NCP_G90_1, NCP_GG_ARCDIST},
        {NCP_G91_1, NCP_GG_ARCDIST}, {NCP_G93, NCP_GG_FEEDMODE}, {NCP_G94, NCP_GG_FEEDMODE},
        {NCP_G95, NCP_GG_FEEDMODE}, {NCP_G20, NCP_GG_UNITS}, {NCP_G21, NCP_GG_UNITS},
        {NCP_G40, NCP_GG_COMP}, {NCP_G41, NCP_GG_COMP}, {NCP_G41_1, NCP_GG_COMP},
        {NCP_G42, NCP_GG_COMP}, {NCP_G42_1, NCP_GG_COMP},
        {NCP_G43, NCP_GG_TLO}, {NCP_G43_1, NCP_GG_TLO}, {NCP_G43_2, NCP_GG_TLO},
        {NCP_G49, NCP_GG_TLO}, {NCP_G98, NCP_GG_RETRACT}, {NCP_G99, NCP_GG_RETRACT},
        {NCP_G54, NCP_GG_COORD}, {NCP_G55, NCP_GG_COORD}, {NCP_G56, NCP_GG_COORD},
        {NCP_G57, NCP_GG_COORD}, {NCP_G58, NCP_GG_COORD}, {NCP_G59, NCP_GG_COORD},
        {NCP_G59_1, NCP_GG_COORD}, {NCP_G59_2, NCP_GG_COORD}, {NCP_G59_3, NCP_GG_COORD},
        {NCP_G61, NCP_GG_CONTROL}, {NCP_G61_1, NCP_GG_CONTROL}, {NCP_G64, NCP_GG_CONTROL},
        {NCP_G96, NCP_GG_SPINDLE}, {NCP_G97, NCP_GG_SPINDLE}, {NCP_G7, NCP_GG_LATHE},
        {NCP_G8, NCP_GG_LATHE},
    };
    memset(ncp_g_group, -1, sizeof ncp_g_group);
    for (size_t k = 0; k < sizeof tab / sizeof tab[0]; k++)
        ncp_g_group[tab[k].code] = tab[k].group;
}

void ncp_words_init(void)
{
    pthread_once(&ncp_g_group_once, ncp_g_table_init);
}

void ncp_words_use_remaps(struct ncp_analyzer *a)
{
    struct ncp_remaps *rs = a->remaps;
    ncp_words_init();
    a->g_group = ncp_g_group;
    if (!rs || !rs->n_g)
        return;
    memcpy(rs->g_group, ncp_g_group, sizeof rs->g_group);
    for (int k = 0; k < rs->n; k++) {
        struct ncp_remap *r = &rs->r[k];
        if (r->g < 0)
            continue;
        r->remappable = ncp_g_group[r->g] < 0; /* rs274's own G codes run built in */
        rs->g_group[r->g] = NCP_G_REMAPPED;
    }
    a->g_group = rs->g_group;
}

/* A remapped G code goes to the motion group whatever rs274 has it in, and
 * without G80's leave to share it (rs274's read_g asks its remaps first). */
static int ncp_add_remapped_g(struct ncp_analyzer *a, const struct ncp_remap *r, int code,
                              uint16_t col)
{
    struct ncp_words *w = &a->w;
    if (w->g[NCP_GG_MOTION] != -1)
        return ncp_an_error(a, col, "Two g codes used from same modal group");
    w->g[NCP_GG_MOTION] = (int16_t)code;
    w->gcol[NCP_GG_MOTION] = col;
    /* a code of its own takes no word but its argspec's, which its remap
     * checks: rs274 skips the checks of the block's other words */
    w->remapped |= r->remappable;
    return NCP_OK;
}

static int ncp_m_group(int m)
{
    switch (m) {
    /* M99: a return where it is first on a line in a sub (flow.c); else an end */
    case NCP_M0: case NCP_M1: case NCP_M2: case NCP_M30: case NCP_M60: case NCP_M99:
        return NCP_MG_STOP;
    case NCP_M6: case NCP_M61: return NCP_MG_TOOL;
    case NCP_M3: case NCP_M4: case NCP_M5: case NCP_M19:
    case NCP_M70: case NCP_M71: case NCP_M72: case NCP_M73: /* rs274's group 7 holds M70-M73 too */
        return NCP_MG_SPINDLE;
    case NCP_M7: case NCP_M8: case NCP_M9: return NCP_MG_COOLANT;
    case NCP_M48: case NCP_M49: case NCP_M50: case NCP_M51: case NCP_M52: case NCP_M53:
        return NCP_MG_OVERRIDE;
    case NCP_M62: case NCP_M63: case NCP_M64: case NCP_M65: case NCP_M66: case NCP_M67: case NCP_M68:
        return NCP_MG_IO;
    default: return m >= NCP_M100 && m <= NCP_M199 ? NCP_MG_USER : -1;
    }
}

static int ncp_eval(struct ncp_analyzer *a, const struct ncp_block *b,
                    const struct ncp_expr *e, double *out)
{
    if (e->is_const) {
        *out = e->value;
        return NCP_OK;
    }
    return ncp_expr_eval(b, e, &a->pops, out, &a->err);
}

static int ncp_add_g(struct ncp_analyzer *a, double v, uint16_t col)
{
    struct ncp_words *w = &a->w;
    double t = v * 10.0;
    int code;
    /* G1, G2, G17.1: whole tenths, where the rounding below changes nothing
     * (floor and ceil are library calls on this target) */
    if (t >= 0.0 && t < 1000.0 && (double)(code = (int)t) == t) {
        /* exact */
    } else if (code = ncp_trunc_int(floor(t)), t - code > 0.999) {
        code = ncp_trunc_int(ceil(t));
    } else if (t - code > 0.001) {
        return ncp_an_error(a, col, "G-code out of range");
    }
    if (code > 999)
        return ncp_an_error(a, col, "G-code out of range");
    if (code < 0)
        return ncp_an_error(a, col, "Negative g code used");
    int g = (int)a->g_group[code]; /* -1: no such code */
    if (g < 0) {
        if (g == NCP_G_REMAPPED) /* rs274 asks its remaps first */
            return ncp_add_remapped_g(a, ncp_remap_of_g(a->remaps, code), code, col);
        return ncp_an_error(a, col, "Unknown g code used");
    }
    if (code == NCP_G80 && w->g[g] != -1)
        return NCP_OK;
    if (w->g[g] != -1 && w->g[g] != NCP_G80)
        return ncp_an_error(a, col, "Two g codes used from same modal group");
    w->g[g] = (int16_t)code;
    w->gcol[g] = col;
    return NCP_OK;
}

/* rs274's read_integer_value (M, T, H, L, a G7x's Q): the floor, or the
 * ceiling when within 0.0001 of it (x86 conversions of the floor, as rs274
 * makes them); anything further from an integer is an error. */
int ncp_integer_word(struct ncp_analyzer *a, double v, uint16_t col, int *out)
{
    if (v >= 0.0 && v < 2147483647.0 && (double)(int)v == v) {
        *out = (int)v; /* a whole number: what the rounding below makes of it */
        return NCP_OK;
    }
    if (ncp_rs274_int(v, out) != 0)
        return ncp_an_error(a, col, "Non integer value for integer");
    return NCP_OK;
}

static int ncp_add_m(struct ncp_analyzer *a, double v, uint16_t col)
{
    struct ncp_words *w = &a->w;
    int m = 0;
    int rc = ncp_integer_word(a, v, col, &m);
    if (rc != NCP_OK)
        return rc;
    if (m < 0)
        return ncp_an_error(a, col, "Negative m code used");
    int g;
    const struct ncp_remap *r = a->remaps ? ncp_remap_of_m(a->remaps, m) : NULL;
    if (r) { /* its group is the REMAP line's */
        static const int slot[11] = {
            -1, -1, -1, -1, NCP_MG_STOP, NCP_MG_IO, NCP_MG_TOOL, NCP_MG_SPINDLE,
            NCP_MG_COOLANT, NCP_MG_OVERRIDE, NCP_MG_USER,
        };
        g = slot[r->group];
        w->remapped |= r->remappable;
    } else {
        if (m > 199)
            return ncp_an_error(a, col, "M-code greater than 199: M%d", m);
        g = ncp_m_group(m);
        if (g < 0)
            return ncp_an_error(a, col, "Unknown m code used: M%d", m);
    }
    if (w->m[g] != -1)
        return ncp_an_error(a, col, "Two m codes used from same modal group");
    w->m[g] = (int16_t)m;
    w->mcol[g] = col;
    w->n_m++;
    return NCP_OK;
}

/* Reader-level value checks rs274 makes while reading each word. */
static int ncp_word_check(struct ncp_analyzer *a, char c, double v, uint16_t col)
{
    /* rs274 reads T, H and L as integers before the sign check */
    if (c == 'T' || c == 'H' || c == 'L') {
        int i = 0;
        int rc = ncp_integer_word(a, v, col, &i);
        if (rc != NCP_OK)
            return rc;
        v = i;
    }
    if (v >= 0.0 || (c == 'H' && v == -1.0)) /* rs274 reads H down to -1 */
        return NCP_OK;
    switch (c) {
    case 'F': return ncp_an_error(a, col, "Negative f word used");
    case 'S': return ncp_an_error(a, col, "Negative spindle speed used");
    case 'T': return ncp_an_error(a, col, "Negative tool id (tool not found)");
    case 'H': return ncp_an_error(a, col, "Negative h word used");
    /* a negative D is legal with G41.1/G42.1 (it swaps the side): cutcomp checks it */
    case 'L': return ncp_an_error(a, col, "Negative l word used");
    /* P may be negative (rs274 2.9 dropped that check: G5 takes signed P);
     * its users treat P-1, rs274's "no P" marker, as missing where rs274 does */
    default: return NCP_OK;
    }
}

/* The name of a named assignment, clamped to the block's pool. */
static const char *ncp_assign_name(const struct ncp_block *b, const struct ncp_assign *as,
                                   size_t *len)
{
    size_t off = as->name_off < NCP_BLOCK_POOL ? as->name_off : NCP_BLOCK_POOL;
    *len = as->name_len <= NCP_BLOCK_POOL - off ? as->name_len : 0;
    return b->pool + off;
}

/* rs274 creates a named assignment target (value 0) the moment it reads it, so
 * an expression to its right on the same line may already read it. Declare the
 * targets standing left of `col`; declaring an existing name does nothing. */
static int ncp_declare_targets_before(struct ncp_analyzer *a, const struct ncp_block *b,
                                      uint16_t col)
{
    unsigned n = b->n_assign < NCP_BLOCK_MAX_ASSIGN ? b->n_assign : NCP_BLOCK_MAX_ASSIGN;
    /* cppcheck follows one caller's block with no assignments and calls the
     * loop dead; other blocks have them */
    // cppcheck-suppress knownConditionTrueFalse
    for (unsigned k = 0; k < n; k++) {
        const struct ncp_assign *as = &b->assign[k];
        if (as->kind != NCP_ASSIGN_NAMED || as->col >= col)
            continue;
        size_t len;
        const char *name = ncp_assign_name(b, as, &len);
        int rc = ncp_params_declare_named(a->params, name, len, &a->err);
        if (rc != NCP_OK) {
            a->err.line = b->line;
            if (a->err.col == 0)
                a->err.col = as->col;
            return rc;
        }
    }
    return NCP_OK;
}

/* rs274 reads a line left to right and stops at the first fault, evaluating
 * each assignment's target and value where it stands. Our words come before
 * the assignments, so a fault found among the words at column `col` gives way
 * to an earlier assignment's: its target's or value's error is the one rs274
 * meets first. The values are only evaluated here, never written. */
static int ncp_assign_fault_before(struct ncp_analyzer *a, const struct ncp_block *b,
                                   uint16_t col)
{
    unsigned n = b->n_assign < NCP_BLOCK_MAX_ASSIGN ? b->n_assign : NCP_BLOCK_MAX_ASSIGN;
    /* cppcheck follows a caller's block with no assignments and calls the
     * loop dead; other blocks have them */
    // cppcheck-suppress knownConditionTrueFalse
    for (unsigned k = 0; k < n; k++) {
        const struct ncp_assign *as = &b->assign[k];
        if (as->col >= col)
            break;
        double v;
        int rc = ncp_declare_targets_before(a, b, (uint16_t)(as->col + 1));
        if (rc == NCP_OK && as->kind == NCP_ASSIGN_NUMBERED) {
            rc = ncp_eval(a, b, &as->index, &v);
            if (rc == NCP_OK && ncp_param_readonly(ncp_trunc_int_round(v)))
                return ncp_an_error(a, as->col, "Parameter is readonly");
        }
        if (rc == NCP_OK)
            rc = ncp_eval(a, b, &as->value, &v);
        if (rc != NCP_OK)
            return rc;
    }
    return NCP_OK;
}

static int ncp_words_collect_upto(struct ncp_analyzer *a, const struct ncp_block *b,
                                  uint16_t limit);

int ncp_words_collect(struct ncp_analyzer *a, const struct ncp_block *b)
{
    int rc = ncp_words_collect_upto(a, b, UINT16_MAX);
    if (rc != NCP_OK && b->n_assign && a->err.col > 0) {
        struct ncp_diag words_err = a->err;
        if (ncp_assign_fault_before(a, b, words_err.col) == NCP_OK)
            a->err = words_err;
    }
    return rc;
}

/* A block the lexer refused at column `col`: the reader's faults of what
 * stands left of it (two codes of one modal group, a negative F, a division
 * by zero...) come first, as rs274 meets them first. NCP_OK when there are
 * none, and the lexer's error stands. */
int ncp_words_fault_before(struct ncp_analyzer *a, const struct ncp_block *b, uint16_t col)
{
    int rc = ncp_words_collect_upto(a, b, col);
    uint16_t at = rc == NCP_OK ? col : a->err.col;
    struct ncp_diag words_err = a->err;
    if (b->n_assign && ncp_assign_fault_before(a, b, at) != NCP_OK)
        return a->err.code ? a->err.code : NCP_ERR_SEMANTIC;
    a->err = words_err;
    return rc;
}

static int ncp_words_collect_upto(struct ncp_analyzer *a, const struct ncp_block *b,
                                  uint16_t limit)
{
    struct ncp_words *w = &a->w;
    w->has = 0;
    w->n_m = 0;
    w->remapped = 0;
    w->line_col = b->n_words ? b->words[0].col : 1;
    memset(w->g, 0xff, sizeof w->g);
    memset(w->m, 0xff, sizeof w->m);
    unsigned n = b->n_words;
    if (n > NCP_BLOCK_MAX_WORDS)
        n = NCP_BLOCK_MAX_WORDS;
    /* the words left of a lexer error only; counted apart so that the
     * loop every block runs stays as it was */
    if (limit != UINT16_MAX) {
        unsigned left = 0;
        while (left < n && b->words[left].col < limit)
            left++;
        n = left;
    }
    for (unsigned k = 0; k < n; k++) {
        const struct ncp_word *wd = &b->words[k];
        double v;
        int rc = b->n_assign ? ncp_declare_targets_before(a, b, wd->col) : NCP_OK;
        if (rc == NCP_OK)
            rc = ncp_eval(a, b, &wd->v, &v);
        if (rc != NCP_OK)
            return rc;
        if (wd->letter == 'G') {
            rc = ncp_add_g(a, v, wd->col);
        } else if (wd->letter == 'M') {
            rc = ncp_add_m(a, v, wd->col);
        } else if ((wd->letter >= 'A' && wd->letter <= 'Z') || wd->letter == '@' ||
                   wd->letter == '^' || wd->letter == '$') {
            int i = NCP_LETTER(wd->letter);
            w->has |= 1u << i;
            w->v[i] = v;
            w->col[i] = wd->col;
            rc = ncp_word_check(a, wd->letter, v, wd->col);
        }
        if (rc != NCP_OK)
            return rc;
    }
    return NCP_OK;
}

/* All values first (pre-block parameters), then the writes in order. */
int ncp_words_assign(struct ncp_analyzer *a, const struct ncp_block *b)
{
    if (b->n_assign == 0)
        return NCP_OK;
    double val[NCP_BLOCK_MAX_ASSIGN];
    int idx[NCP_BLOCK_MAX_ASSIGN] = {0}; /* set for the numbered targets, read only for them */
    unsigned n = b->n_assign;
    if (n > NCP_BLOCK_MAX_ASSIGN)
        n = NCP_BLOCK_MAX_ASSIGN;
    for (unsigned k = 0; k < n; k++) {
        const struct ncp_assign *as = &b->assign[k];
        int rc = ncp_declare_targets_before(a, b, (uint16_t)(as->col + 1));
        if (rc == NCP_OK && as->kind == NCP_ASSIGN_NUMBERED) {
            double iv;
            rc = ncp_eval(a, b, &as->index, &iv);
            idx[k] = ncp_trunc_int_round(iv);
            /* rs274 refuses these as it reads the target, before the value */
            if (rc == NCP_OK && ncp_param_readonly(idx[k]))
                return ncp_an_error(a, as->col, "Parameter is readonly");
        }
        if (rc == NCP_OK)
            rc = ncp_eval(a, b, &as->value, &val[k]);
        if (rc != NCP_OK)
            return rc;
    }
    for (unsigned k = 0; k < n; k++) {
        const struct ncp_assign *as = &b->assign[k];
        int rc;
        a->err.line = b->line;
        if (as->kind == NCP_ASSIGN_NUMBERED) {
            rc = ncp_params_set(a->params, idx[k], val[k], &a->err);
        } else {
            size_t len;
            const char *name = ncp_assign_name(b, as, &len);
            rc = ncp_params_set_named(a->params, name, len, val[k], &a->err);
        }
        if (rc != NCP_OK) {
            a->err.line = b->line;
            if (a->err.col == 0)
                a->err.col = as->col;
            return rc;
        }
    }
    return NCP_OK;
}
