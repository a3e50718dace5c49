/* O-word control flow, modelled on rs274's own: one table of O-word labels
 * (subroutine names, and loop/if labels scoped by the subroutine they are in),
 * a "skip forward to label L" state, and jumps back to a label's recorded block.
 * Following that model rather than a structured parser keeps rs274's results,
 * including its error messages and its corner cases, for any program.
 *
 * Blocks come from the pre-lexed feed while execution moves forward through new
 * text; a jump back re-reads the text from the jump target (with a small cache
 * of lexed blocks for loop bodies) until it is back at the feed's position. */
#include "flow.h"
#include "codes.h"

#include "ncpar/blocks.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* rs274 -g runs with the block delete switch off: '/' blocks are executed. */
#define FLOW_BLOCK_DELETE 0
#define FLOW_DEFAULT_MAX_DEPTH 10u    /* rs274: INTERP_SUB_ROUTINE_LEVELS */
#define FLOW_NAME_MAX NCP_BLOCK_POOL
#define FLOW_LABEL_MAX (2 * FLOW_NAME_MAX + 2)

/* file 0 is the program; others are subroutine files (o<name> call finds
 * name.ngc when no sub of that name was defined yet, as rs274 does) */
struct flow_pos {
    uint64_t off;
    uint32_t line;
    uint32_t file;
};

/* One entry of the label table: where a sub, loop or if was first seen. */
struct flow_label {
    uint32_t hash, key_off, key_len;  /* key_len 0: empty slot */
    uint8_t type;                     /* enum ncp_oword_kind that defined it */
    int32_t repeat_count;             /* -1: not counting */
    uint32_t line, file;
    uint64_t off;
    uint64_t iterations;              /* of the current run of the loop */
    uint64_t idle_laps;               /* jumps back to it that ran no iteration */
    /* A loop's whole text, once a skip from its head to its end line found
     * nothing in it that a skip would notice (see "Loop ends" below): a later
     * skip over it goes straight past its end line. Valid while the table
     * holds the same labels (region_epoch == labels.epoch). */
    uint64_t end_next;                /* 0: not known */
    uint32_t end_next_line, region_epoch;
};

struct flow_labels {
    struct flow_label *slots;
    uint32_t cap, count;
    uint32_t epoch;                   /* bumped whenever a label is added or all go */
    char *arena;
    size_t used, acap;
};

/* How a call level was entered (rs274's call_type): frame 0 by none. */
enum { FLOW_CT_NONE, FLOW_CT_OWORD, FLOW_CT_M98 };

struct flow_frame {
    struct flow_pos ret;              /* block after the call */
    uint8_t call_type;                /* FLOW_CT_* */
    int32_t m98_loops;                /* M98 L repeats left of a call made from
                                         this level (rs274's m98_loop_counter), -1 */
    uint16_t name_len;
    char name[FLOW_NAME_MAX];         /* the called sub: scope of its labels */
    int inline_prev;                  /* an inline call into this level: the
                                         inline level it interrupted, -1 */
};

/* A skip from a loop's head to its end line, noting whether what lies
 * between is only nested structure a skip passes over unchanged: every
 * O-word line there closes or continues one opened there (a stack of their
 * labels, in an arena), nothing else but calls. */
struct flow_scan {
    int on;
    uint32_t epoch;                   /* labels.epoch when it started */
    struct flow_label *op;            /* the loop (valid while epoch holds) */
    struct { uint32_t off, len; uint8_t kind; } *open;
    uint32_t n_open, open_cap;
    char *arena;
    size_t used, acap;
};

/* Text-valued state ("skip to label", "seeking sub", "defining sub"). */
struct flow_name {
    int on;
    uint16_t len;
    char s[FLOW_LABEL_MAX];
};

struct ncp_flow {
    struct ncp_block_feed feed;
    const struct ncp_source *src;     /* the file the current block is in */
    const struct ncp_source *prog;    /* the program's own (file 0) */
    struct ncp_sub_files *files;      /* subroutine files, 1 .. (made at the first) */
    const char *sub_path;             /* colon-separated folders, after the current one */
    struct ncp_params *params;
    struct ncp_param_ops pops;
    struct ncp_flow_frames hooks;
    struct ncp_flow_m98_reader m98_reader;
    uint32_t max_loops, max_depth;
    int oword_nargs;                  /* [RS274NGC]OWORD_NARGS: each call's #<n_args> */
    int no_fanuc;                     /* [RS274NGC]DISABLE_FANUC_STYLE_SUB */
    int (*cancel)(void *ctx);
    void *cancel_ctx;
    uint32_t ticks;                   /* blocks seen, for the stop request */

    struct flow_pos cur;              /* next block to execute */
    struct flow_pos feed_pos;         /* next block the feed will deliver */
    int feed_done, feed_held;
    struct ncp_block_reread *reread; /* blocks read again, lexed once */
    struct ncp_block *fanuc_blk;      /* an M_VALUE line read again as M98/M99 */

    struct flow_labels labels;
    struct flow_frame *frames;        /* [1 .. level] */
    int frames_cap, level;

    struct flow_name skip;            /* skipping forward to this label */
    struct flow_scan scan;            /* ... from a loop's head, learning its end */
    struct flow_name seek_sub;        /* ... looking for this sub's definition */
    struct flow_name defining;        /* inside this sub's definition (level 0) */
    /* rs274 accepts a stray return at level 0 once any call has returned there
     * (its "current sub" is then an empty name, no longer none) */
    int in_sub_context;
    uint32_t skip_start;
    /* the call that started the seek: where an end of file before the sub
     * is reported (rs274 counts a subroutine file's lines from 0) */
    struct flow_pos seek_call;
    uint16_t seek_call_col;
    int executed_if, doing_break, doing_continue;
    uint64_t jump_target;             /* offset of the block a loop jumped to */
    int by_jump;                      /* the current block was reached that way */
    double test_value;
    double args[NCP_OWORD_MAX_ARGS];
    int nargs;
    int m98_p, m98_l;                 /* the M98 line being run: sub number, L or -1 */

    int inline_level;                 /* an inline call returns to this level, or -1 */
    char label[FLOW_LABEL_MAX];       /* label of the block being run */
    size_t label_len;
    char number[16];                  /* its O number when computed ("o#1"), as text */
    int ended_at_percent;             /* the closing '%' ended a search for a sub */
    const char *call_path;            /* a call's name as written (in its block): */
    size_t call_path_len;             /* the path of the file it may be in */
};

static void ncp_flow_name_set(struct flow_name *n, const char *s, size_t len)
{
    if (len >= sizeof n->s)
        len = sizeof n->s - 1;
    memcpy(n->s, s, len);
    n->s[len] = '\0';
    n->len = (uint16_t)len;
    n->on = 1;
}

static int ncp_flow_name_eq(const struct flow_name *n, const char *s, size_t len)
{
    return n->on && n->len == len && memcmp(n->s, s, len) == 0;
}

static const struct ncp_source *ncp_flow_file_src(const struct ncp_flow *f, uint32_t file)
{
    return file == 0 ? f->prog : ncp_sub_files_src(f->files, file);
}

static const char *ncp_flow_file_name(const struct ncp_flow *f, uint32_t file)
{
    const char *n = file == 0 ? f->prog->name : ncp_sub_files_name(f->files, file);
    return n ? n : "";
}

/* Every move of the position goes through here: it may change file. */
static void ncp_flow_go_to(struct ncp_flow *f, struct flow_pos p)
{
    f->cur = p;
    f->src = ncp_flow_file_src(f, p.file);
}

/* ======================================================================
 * Label table
 * ====================================================================== */

static uint32_t ncp_flow_hash(const char *s, size_t n)
{
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= 16777619u;
    }
    return h;
}

static struct flow_label *ncp_flow_labels_find(const struct flow_labels *t, const char *k,
                                      size_t len)
{
    if (!t->cap)
        return NULL;
    uint32_t h = ncp_flow_hash(k, len), mask = t->cap - 1;
    for (uint32_t i = h & mask;; i = (i + 1) & mask) {
        struct flow_label *e = &t->slots[i];
        if (!e->key_len)
            return NULL;
        if (e->hash == h && e->key_len == len && memcmp(t->arena + e->key_off, k, len) == 0)
            return e;
    }
}

static int ncp_flow_labels_grow(struct flow_labels *t)
{
    uint32_t ncap = t->cap ? t->cap * 2 : 64;
    struct flow_label *ns = calloc(ncap, sizeof *ns);
    if (!ns)
        return -1;
    for (uint32_t i = 0; i < t->cap; i++) {
        if (!t->slots[i].key_len)
            continue;
        uint32_t j = t->slots[i].hash & (ncap - 1);
        while (ns[j].key_len)
            j = (j + 1) & (ncap - 1);
        ns[j] = t->slots[i];
    }
    free(t->slots);
    t->slots = ns;
    t->cap = ncap;
    return 0;
}

/* Add a new key (the caller checked it is absent). NULL when out of memory. */
static struct flow_label *ncp_flow_labels_add(struct flow_labels *t, const char *k, size_t len)
{
    if ((t->count + 1) * 2 > t->cap && ncp_flow_labels_grow(t) != 0)
        return NULL;
    if (t->used + len > t->acap) {
        size_t ncap = t->acap ? t->acap : 1024;
        while (ncap < t->used + len)
            ncap *= 2;
        char *na = realloc(t->arena, ncap);
        if (!na)
            return NULL;
        t->arena = na;
        t->acap = ncap;
    }
    memcpy(t->arena + t->used, k, len);
    uint32_t h = ncp_flow_hash(k, len), mask = t->cap - 1, i = h & mask;
    while (t->slots[i].key_len)
        i = (i + 1) & mask;
    struct flow_label *e = &t->slots[i];
    *e = (struct flow_label){ .hash = h, .key_off = (uint32_t)t->used,
                              .key_len = (uint32_t)len, .repeat_count = -1 };
    t->used += len;
    t->count++;
    t->epoch++;
    return e;
}

static void ncp_flow_labels_clear(struct flow_labels *t)
{
    if (t->count)
        memset(t->slots, 0, t->cap * sizeof *t->slots);
    t->count = 0;
    t->used = 0;
    t->epoch++;
}

/* ======================================================================
 * Block source: the feed, or re-reading the text behind it
 * ====================================================================== */

static void ncp_flow_release_feed(struct ncp_flow *f)
{
    if (f->feed_held) {
        f->feed_held = 0;
        if (f->feed.release)
            f->feed.release(f->feed.ctx);
    }
}

static int ncp_flow_from_feed(struct ncp_flow *f, const struct ncp_block **out)
{
    if (f->feed_done)
        return NCP_END;
    const struct ncp_block *b = f->feed.next(f->feed.ctx);
    if (!b) {
        f->feed_done = 1;
        return NCP_END;
    }
    f->feed_held = 1;
    uint64_t next = f->src->end;
    struct ncp_span sp;
    if (b->length < 0xffff) /* length is exact: no second search of the line */
        next = ncp_source_after(f->src, b->offset, b->length);
    else if (ncp_source_span(f->src, b->offset, b->line, &sp) == 0)
        next = sp.next;
    /* Field by field: copying feed_pos whole right after these narrow
     * stores is a wide load the stores cannot forward to, a stall per block. */
    f->feed_pos.off = f->cur.off = next;
    f->feed_pos.line = f->cur.line = b->line + 1;
    *out = b;
    return NCP_OK;
}

/* Sets *out to NULL for a block skipped without lexing it (skipping, and its
 * text cannot hold an O-word). */
static int ncp_flow_from_text(struct ncp_flow *f, int skipping, const struct ncp_block **out,
                     struct ncp_diag *d)
{
    if (!f->reread && !(f->reread = ncp_block_reread_new()))
        return ncp_diag_set(d, NCP_ERR_IO, f->cur.line, 0, "out of memory");
    if (ncp_block_reread_at(f->reread, f->src, f->cur.file, skipping, &f->cur.off,
                            &f->cur.line, out) != 0)
        return NCP_END;
    return NCP_OK;
}

static int ncp_flow_fetch(struct ncp_flow *f, int skipping, const struct ncp_block **out,
                 struct ncp_diag *d)
{
    ncp_flow_release_feed(f);
    if (f->cur.file == 0 && f->cur.off >= f->feed_pos.off)
        return ncp_flow_from_feed(f, out);
    return ncp_flow_from_text(f, skipping, out, d);
}

/* ======================================================================
 * Messages
 * ====================================================================== */

static const char *ncp_flow_kind_name(int kind)
{
    static const char *const names[] = {
        [NCP_O_NONE] = "none", [NCP_O_SUB] = "sub", [NCP_O_ENDSUB] = "endsub",
        [NCP_O_CALL] = "call", [NCP_O_RETURN] = "return", [NCP_O_IF] = "if",
        [NCP_O_ELSEIF] = "elseif", [NCP_O_ELSE] = "else", [NCP_O_ENDIF] = "endif",
        [NCP_O_WHILE] = "while", [NCP_O_ENDWHILE] = "endwhile", [NCP_O_DO] = "do",
        [NCP_O_REPEAT] = "repeat", [NCP_O_ENDREPEAT] = "endrepeat",
        [NCP_O_BREAK] = "break", [NCP_O_CONTINUE] = "continue",
        [NCP_O_FANUC] = "", [NCP_O_M98] = "M98", [NCP_O_M99] = "M99",
    };
    if (kind < 0 || kind >= (int)(sizeof names / sizeof names[0]) || !names[kind])
        return "?";
    return names[kind];
}

/* The block's text as rs274 quotes it: trailing blanks cut, kept short. */
static int ncp_flow_line_text(const struct ncp_flow *f, const struct ncp_block *b,
                     const char **s)
{
    size_t n = b->length;
    if (b->offset > f->src->len || n > f->src->len - b->offset)
        n = 0;
    *s = f->src->text + (n ? b->offset : 0);
    while (n > 0 && ((*s)[n - 1] == ' ' || (*s)[n - 1] == '\t' || (*s)[n - 1] == '\r'))
        n--;
    return n > 80 ? 80 : (int)n;
}

static int ncp_flow_oword_error(const struct ncp_block *b, const char *what,
                       struct ncp_diag *d)
{
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col, "%s", what);
}

/* [RS274NGC]DISABLE_FANUC_STYLE_SUB: rs274 refuses M98, M99 and a bare
 * O-word line as it reads them, skipped or not, in its words. */
static int ncp_flow_no_fanuc(const struct ncp_block *b, int kind, struct ncp_diag *d)
{
    if (kind == NCP_O_M98)
        return ncp_flow_oword_error(b, "DISABLE_FANUC_STYLE_SUB set in INI file, but found m98", d);
    if (kind == NCP_O_M99)
        return ncp_flow_oword_error(b, "DISABLE_FANUC_STYLE_SUB set in INI file, but found m99", d);
    if (kind == NCP_O_FANUC)
        return ncp_flow_oword_error(
            b, "DISABLE_FANUC_STYLE_SUB disabled in INI file, but found bare O-word", d);
    return NCP_OK;
}

static int ncp_flow_err_undefined(struct ncp_flow *f, const struct ncp_block *b,
                         struct ncp_diag *d)
{
    const char *s;
    int n = ncp_flow_line_text(f, b, &s);
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                        "undefined O-word label: '%.*s'", n, s);
}

/* "found 'while' in line 3" */
static int ncp_flow_err_mismatch(struct ncp_flow *f, const struct ncp_block *b,
                        const char *what, const struct flow_label *op,
                        struct ncp_diag *d)
{
    const char *s;
    int n = ncp_flow_line_text(f, b, &s);
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                        "%s: '%.*s' (found '%s' in line %u)", what, n, s,
                        ncp_flow_kind_name(op->type), op->line);
}

/* The O-word's name as text: a computed number ("o#1") is the one
 * ncp_flow_read_number last read. */
static const char *ncp_flow_oword_name(const struct ncp_flow *f, const struct ncp_block *b,
                                       size_t *len)
{
    if (b->oword.name_computed) {
        *len = strlen(f->number);
        return f->number;
    }
    *len = b->oword.name_len;
    return b->pool + b->oword.name_off;
}

/* How a user wrote the O-word: o100 or o<name>. */
static void ncp_flow_display_name(const struct ncp_flow *f, const struct ncp_block *b,
                                  char *buf, size_t cap)
{
    size_t n, i = 0;
    const char *s = ncp_flow_oword_name(f, b, &n);
    if (n > 60)
        n = 60;
    while (i < n && s[i] >= '0' && s[i] <= '9')
        i++;
    if (n > 0 && i == n)
        snprintf(buf, cap, "o%.*s", (int)n, s);
    else
        snprintf(buf, cap, "o<%.*s>", (int)n, s);
}

/* ======================================================================
 * The O-word state machine
 * ====================================================================== */

static int ncp_flow_is_global_kind(int kind)
{
    return kind == NCP_O_SUB || kind == NCP_O_ENDSUB || kind == NCP_O_CALL ||
           kind == NCP_O_RETURN || kind >= NCP_O_FANUC;
}

/* Subroutine names are global; other labels belong to the subroutine they are
 * written in (the called one, or the one being defined), as "sub#label". */
static void ncp_flow_make_label(struct ncp_flow *f, const struct ncp_block *b)
{
    size_t len, n = 0;
    const char *name = ncp_flow_oword_name(f, b, &len);
    char num[16];
    if (b->oword.kind == NCP_O_M98) {         /* the sub's number from P */
        len = (size_t)snprintf(num, sizeof num, "%d", f->m98_p);
        name = num;
    } else if (b->oword.kind == NCP_O_M99) {  /* the sub it is in */
        name = f->frames[f->level].name;
        len = f->frames[f->level].name_len;
    }
    if (b->oword.kind == NCP_O_CALL) {
        f->call_path = name;
        f->call_path_len = len;
        /* o<../lib/up> call: rs274 looks for the file by the whole path
         * but calls the sub by the file's own name, "up" */
        const char *slash = memrchr(name, '/', len);
        if (slash) {
            len -= (size_t)(slash + 1 - name);
            name = slash + 1;
        }
    }
    if (len > FLOW_NAME_MAX)
        len = FLOW_NAME_MAX;
    if (!ncp_flow_is_global_kind(b->oword.kind)) {
        if (f->level > 0) {
            memcpy(f->label, f->frames[f->level].name, f->frames[f->level].name_len);
            n = f->frames[f->level].name_len;
        } else if (f->defining.on) {
            memcpy(f->label, f->defining.s, f->defining.len);
            n = f->defining.len;
        }
        f->label[n++] = '#';
    }
    memcpy(f->label + n, name, len);
    f->label_len = n + len;
    f->label[f->label_len] = '\0';
}

static int ncp_flow_skipping_other(const struct ncp_flow *f)
{
    return f->skip.on && !ncp_flow_name_eq(&f->skip, f->label, f->label_len);
}

static void ncp_flow_skip_to_label(struct ncp_flow *f, const struct ncp_block *b)
{
    ncp_flow_name_set(&f->skip, f->label, f->label_len);
    f->skip_start = b->line;
    f->scan.on = 0;
}

static int ncp_flow_eval(struct ncp_flow *f, const struct ncp_block *b, const struct ncp_expr *e,
                double *v, struct ncp_diag *d)
{
    if (e->is_const) {
        *v = e->value;
        return NCP_OK;
    }
    return ncp_expr_eval(b, e, &f->pops, v, d);
}

/* While rs274 skips over a subroutine definition it still evaluates the
 * endsub/return value, but an undefined named parameter reads as 0 there. */
static int ncp_flow_lenient_get_named(void *ctx, const char *name, size_t len, double *out,
                             struct ncp_diag *d)
{
    const struct ncp_params *p = ctx;
    if (!ncp_params_exists(p, name, len)) {
        *out = 0.0;
        return NCP_OK;
    }
    return ncp_params_get_named(p, name, len, out, d);
}

static int ncp_flow_eval_lenient(struct ncp_flow *f, const struct ncp_block *b,
                        const struct ncp_expr *e, double *v, struct ncp_diag *d)
{
    if (e->is_const) {
        *v = e->value;
        return NCP_OK;
    }
    struct ncp_param_ops ops = ncp_params_ops(f->params);
    ops.get_named = ncp_flow_lenient_get_named;
    return ncp_expr_eval(b, e, &ops, v, d);
}

static struct flow_label *ncp_flow_find_label(struct ncp_flow *f)
{
    return ncp_flow_labels_find(&f->labels, f->label, f->label_len);
}

static int ncp_flow_save_label(struct ncp_flow *f, const struct ncp_block *b,
                      struct flow_label **out, struct ncp_diag *d)
{
    const struct flow_label *old = ncp_flow_find_label(f);
    if (old) {
        const char *file = ncp_flow_file_name(f, f->cur.file);
        if (old->line == b->line && old->file == f->cur.file)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                                "File:%s line:%u sub: o|%s| found in illegal location",
                                file, b->line, f->label);
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                            "File:%s line:%u redefining sub: o|%s| already defined in "
                            "file:%s", file, b->line, f->label, ncp_flow_file_name(f, old->file));
    }
    struct flow_label *e = ncp_flow_labels_add(&f->labels, f->label, f->label_len);
    if (!e)
        return ncp_diag_set(d, NCP_ERR_IO, b->line, 0, "out of memory");
    e->type = b->oword.kind;
    e->line = b->line;
    e->file = f->cur.file;
    e->off = b->offset;
    if (out)
        *out = e;
    return NCP_OK;
}

static void ncp_flow_jump_to(struct ncp_flow *f, const struct flow_label *op)
{
    ncp_flow_go_to(f, (struct flow_pos){ op->off, op->line, op->file });
    f->jump_target = op->off;
}

/* Runaway guard, per run of a loop. A run starts when its first line is
 * reached by falling into it, not by a jump back: so a loop left by return
 * starts afresh next time, while rs274's leftover continue flag, which can
 * send an exhausted loop back to its start for ever, keeps counting. */
static void ncp_flow_loop_entered(const struct ncp_flow *f, struct flow_label *op)
{
    if (!f->by_jump)
        op->iterations = op->idle_laps = 0;
}

static int ncp_flow_runaway(const struct ncp_flow *f, const struct ncp_block *b,
                   const struct flow_label *op, struct ncp_diag *d)
{
    char name[80];
    ncp_flow_display_name(f, b, name, sizeof name);
    return ncp_diag_set(d, NCP_ERR_LIMIT, op->line, 0,
                        "loop %s at line %u repeated more than %u times: runaway loop? "
                        "(raise the limit with --max-loops N if intended)",
                        name, op->line, f->max_loops);
}

/* A stop request is asked every CANCEL_BLOCKS blocks the flow hands on or
 * passes over (the laps of a loop, the lines a skip or a search reads):
 * a block costs a microsecond or so, a lap of a loop at least two blocks,
 * so a stop is seen well within a millisecond, in a loop or not, at the
 * cost of a counter per block. */
#define CANCEL_BLOCKS 64u

static int ncp_flow_cancelled(const struct ncp_flow *f, const struct ncp_block *b,
                              struct ncp_diag *d)
{
    if (!f->cancel(f->cancel_ctx))
        return NCP_OK;
    return ncp_diag_set(d, NCP_ERR_LIMIT, b->line, 0, "stopped on request at line %u",
                        b->line);
}

static int ncp_flow_count_iteration(struct ncp_flow *f, const struct ncp_block *b,
                           struct flow_label *op, struct ncp_diag *d)
{
    if (++op->iterations > f->max_loops)
        return ncp_flow_runaway(f, b, op, d);
    return NCP_OK;
}

/* A loop head reached by a jump back whose test ends the loop: once per run
 * normally, but an end line of the same name further down (rs274 skips to
 * the first) can send control back to it for ever, each lap running what
 * lies between the two and no iteration. rs274 loops; we count those laps
 * against the same limit. */
static int ncp_flow_count_idle_lap(struct ncp_flow *f, const struct ncp_block *b,
                          struct flow_label *op, struct ncp_diag *d)
{
    if (!f->by_jump)
        return NCP_OK;
    if (++op->idle_laps > f->max_loops)
        return ncp_flow_runaway(f, b, op, d);
    return NCP_OK;
}

/* What rs274 does while reading an O-word line: evaluate its expressions unless
 * it is being skipped. *ignore = 1 when the block has no effect at all. */
static int ncp_flow_read_oword(struct ncp_flow *f, const struct ncp_block *b, int *ignore,
                      struct ncp_diag *d)
{
    const struct ncp_oword *o = &b->oword;
    double v;
    int rc;
    *ignore = 0;
    switch (o->kind) {
    case NCP_O_SUB:
    case NCP_O_FANUC:
        if (f->defining.on)
            return ncp_flow_oword_error(b, "Nested subroutine definition", d);
        return NCP_OK;
    case NCP_O_M99: /* read as an O-word in a sub only (level > 0) */
        if (f->defining.on)
            return ncp_flow_oword_error(b, "Found 'M99' instead of 'O endsub' after 'O sub'", d);
        if (ncp_flow_skipping_other(f)) {
            *ignore = 1;
            return NCP_OK;
        }
        ncp_params_set_return(f->params, 0.0, 0);
        /* rs274 looks at the rest of the line unless it is skipping */
        if (!f->skip.on && o->tail_col)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, o->tail_col,
                                "Unexpected character after O-word");
        return NCP_OK;
    case NCP_O_ENDSUB:
    case NCP_O_RETURN:
        if (ncp_flow_skipping_other(f)) {
            *ignore = 1;
            return NCP_OK;
        }
        if (!o->has_cond) {
            ncp_params_set_return(f->params, 0.0, 0);
            return NCP_OK;
        }
        rc = f->defining.on && f->level == 0 ? ncp_flow_eval_lenient(f, b, &o->cond, &v, d)
                                              : ncp_flow_eval(f, b, &o->cond, &v, d);
        if (rc == NCP_OK)
            ncp_params_set_return(f->params, v, 1);
        return rc;
    default:
        break;
    }
    if (f->defining.on) {
        *ignore = 1;
        return NCP_OK;
    }
    switch (o->kind) {
    case NCP_O_CALL:
        if (f->skip.on) {
            *ignore = 1;
            return NCP_OK;
        }
        f->nargs = o->nargs > NCP_OWORD_MAX_ARGS ? NCP_OWORD_MAX_ARGS : o->nargs;
        for (int i = 0; i < f->nargs; i++) {
            rc = ncp_flow_eval(f, b, &o->args[i], &f->args[i], d);
            if (rc != NCP_OK)
                return rc;
        }
        return NCP_OK;
    case NCP_O_WHILE:
    case NCP_O_REPEAT:
    case NCP_O_IF:
    case NCP_O_ELSEIF:
        if (ncp_flow_skipping_other(f)) {
            *ignore = 1;
            return NCP_OK;
        }
        if (!o->has_cond) {
            char msg[64];
            snprintf(msg, sizeof msg, "Left bracket missing after '%s'", ncp_flow_kind_name(o->kind));
            return ncp_flow_oword_error(b, msg, d);
        }
        return ncp_flow_eval(f, b, &o->cond, &f->test_value, d);
    default:
        return NCP_OK;
    }
}

/* A sub's first line (o-sub or Fanuc): where a call was skipping ahead to
 * it, it is defined from now on and the skipping ends. */
static int ncp_flow_reach_sub(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    if (f->skip.on) {
        int rc = ncp_flow_save_label(f, b, NULL, d);
        if (rc != NCP_OK)
            return rc;
        f->skip.on = 0;
    }
    f->seek_sub.on = 0;
    return NCP_OK;
}

static int ncp_flow_do_sub(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    if (f->frames[f->level].call_type == FLOW_CT_M98)
        return ncp_flow_oword_error(b, "'O.... sub' subroutine must be called with 'O.... call'", d);
    int reached = ncp_flow_reach_sub(f, b, d);
    if (reached != NCP_OK)
        return reached;
    if (f->level > 0)
        return NCP_OK;           /* the called sub's own first line */
    int rc = ncp_flow_save_label(f, b, NULL, d);
    if (rc != NCP_OK)
        return rc;
    ncp_flow_skip_to_label(f, b);
    ncp_flow_name_set(&f->defining, f->label, f->label_len);
    f->in_sub_context = 1;
    return NCP_OK;
}

/* A bare "O100" line: where an M98 call was seeking it, the sub is defined
 * from here on; otherwise (at level 0, or further down in a sub) rs274 just
 * reads on into it, defining nothing. */
static int ncp_flow_do_fanuc(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    if (f->frames[f->level].call_type == FLOW_CT_OWORD)
        return ncp_flow_oword_error(b, "Fanuc 'O....' subroutine must be called with 'M98'", d);
    return ncp_flow_reach_sub(f, b, d);
}

static int ncp_flow_do_return(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    if (f->level == 0 && !f->in_sub_context) {
        const char *s;
        int n = ncp_flow_line_text(f, b, &s);
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                            "not in a subroutine definition: '%.*s'", n, s);
    }
    if (f->level > 0) {
        /* a sub is left the way it was entered */
        int ct = f->frames[f->level].call_type;
        if (ct == FLOW_CT_M98 && b->oword.kind != NCP_O_M99)
            return ncp_flow_oword_error(b, "Fanuc 'O....' subroutine definition must end with 'M99'", d);
        if (ct == FLOW_CT_OWORD && b->oword.kind == NCP_O_M99)
            return ncp_flow_oword_error(b, "'O.... endsub' or 'O.... return' must follow 'O.... sub' "
                                  "subroutine definition", d);
    }
    if (f->skip.on && b->oword.kind == NCP_O_ENDSUB)
        f->skip.on = 0;
    if (f->level > 0) {
        ncp_params_pop_call(f->params);
        ncp_flow_go_to(f, f->frames[f->level].ret);
        f->level--;
        if (f->level == 0)
            f->in_sub_context = 1;
        if (f->hooks.left)
            f->hooks.left(f->hooks.ctx, f->level + 1);
    } else if (b->oword.kind == NCP_O_ENDSUB) {
        if (!f->defining.on)
            return ncp_flow_oword_error(b, "Not in subroutine definition", d);
        f->skip.on = 0;
        f->defining.on = 0;
        f->in_sub_context = 0;
    }
    return NCP_OK;
}

static int ncp_flow_grow_frames(struct ncp_flow *f)
{
    if (f->level + 1 < f->frames_cap)
        return 0;
    int ncap = f->frames_cap ? f->frames_cap * 2 : 16;
    struct flow_frame *nf = realloc(f->frames, (size_t)ncap * sizeof *nf);
    if (!nf)
        return -1;
    f->frames = nf;
    f->frames_cap = ncap;
    return 0;
}

/* The called name's file (the block source looks for it as rs274 does);
 * *file = 0 when there is none. */
static int ncp_flow_open_sub_file(struct ncp_flow *f, const struct ncp_block *b, uint32_t *file,
                         struct ncp_diag *d)
{
    const char *name = f->label;
    size_t name_len = f->label_len;
    if (b->oword.kind == NCP_O_CALL) {
        name = f->call_path;
        name_len = f->call_path_len;
    }
    if (!f->files && !(f->files = ncp_sub_files_new()))
        return ncp_diag_set(d, NCP_ERR_IO, b->line, 0, "out of memory");
    return ncp_sub_files_open(f->files, name, name_len, f->sub_path, b->line, b->oword.col,
                              file, d);
}

/* A new call level for the sub named by the label: a copy of the arguments
 * for o-word calls, the caller's #1..#30 for M98 (ct). */
static int ncp_flow_enter_call(struct ncp_flow *f, const struct ncp_block *b, int ct,
                      struct ncp_diag *d)
{
    if ((uint32_t)f->level + 1 >= f->max_depth)
        return ncp_diag_set(d, NCP_ERR_LIMIT, b->line, b->oword.col,
                            "Too many subroutine levels");
    if (ncp_flow_grow_frames(f) != 0)
        return ncp_diag_set(d, NCP_ERR_IO, b->line, 0, "out of memory");
    int rc = ct == FLOW_CT_M98 ? ncp_params_push_shared(f->params, d)
                               : ncp_params_push_call(f->params, f->args, f->nargs, d);
    if (rc == NCP_OK && f->oword_nargs)
        rc = ncp_params_set_nargs(f->params, ct == FLOW_CT_M98 ? 0 : f->nargs, d);
    if (rc != NCP_OK)
        return rc;
    struct flow_frame *fr = &f->frames[++f->level];
    if (f->hooks.entered)
        f->hooks.entered(f->hooks.ctx, f->level);
    fr->ret = f->cur;
    fr->call_type = (uint8_t)ct;
    fr->m98_loops = -1;
    size_t n = f->label_len < FLOW_NAME_MAX ? f->label_len : FLOW_NAME_MAX;
    memcpy(fr->name, f->label, n);
    fr->name_len = (uint16_t)n;
    return NCP_OK;
}

/* Go to the called sub's definition: its recorded line, or, not seen yet,
 * rs274 looks for a file of its name first, and reads that from its start
 * for the definition; without one it reads on here. */
static int ncp_flow_go_to_sub(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    f->skip.on = 0;
    const struct flow_label *op = ncp_flow_find_label(f);
    if (op) {
        ncp_flow_jump_to(f, op);
        return NCP_OK;
    }
    uint32_t file = 0;
    int rc = ncp_flow_open_sub_file(f, b, &file, d);
    if (rc != NCP_OK)
        return rc;
    ncp_flow_skip_to_label(f, b);
    ncp_flow_name_set(&f->seek_sub, f->label, f->label_len);
    f->seek_call = (struct flow_pos){ b->offset, b->line, f->cur.file };
    f->seek_call_col = b->oword.col;
    if (file) {
        const struct ncp_source *s = ncp_flow_file_src(f, file);
        ncp_flow_go_to(f, (struct flow_pos){ s->begin, s->begin_line, file });
        f->skip_start = 0; /* rs274 counts lines afresh in the new file */
    }
    return NCP_OK;
}

static int ncp_flow_do_call(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    int rc = ncp_flow_enter_call(f, b, FLOW_CT_OWORD, d);
    return rc == NCP_OK ? ncp_flow_go_to_sub(f, b, d) : rc;
}

/* M98 P.. [L..], as rs274's execute_call: with L, the calling level counts
 * the repeats down and, while some are left, returns to the M98 line itself,
 * which then runs again (its P read anew); L0 enters the call level and
 * reads on after the M98 line, without going to the sub. */
static int ncp_flow_do_m98(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    if (f->m98_l > 0 && (uint32_t)f->m98_l > f->max_loops)
        return ncp_diag_set(d, NCP_ERR_LIMIT, b->line, b->oword.col,
                            "M98 L%d repeats a sub more than %u times: runaway loop? "
                            "(raise the limit with --max-loops N if intended)",
                            f->m98_l, f->max_loops);
    struct flow_pos here = { b->offset, b->line, f->cur.file };
    int rc = ncp_flow_enter_call(f, b, FLOW_CT_M98, d);
    if (rc != NCP_OK)
        return rc;
    if (f->m98_l >= 0) {
        struct flow_frame *caller = &f->frames[f->level - 1];
        if (caller->m98_loops == -1)
            caller->m98_loops = f->m98_l;
        if (--caller->m98_loops > 0)
            f->frames[f->level].ret = here;
        else
            caller->m98_loops = -1;
        if (f->m98_l == 0)
            return NCP_OK;
    }
    return ncp_flow_go_to_sub(f, b, d);
}

/* The M98 line's words, read before anything else is done with it. */
static int ncp_flow_read_m98(struct ncp_flow *f, const struct ncp_block *b, int skipping,
                    struct ncp_diag *d)
{
    f->m98_p = 0;
    f->m98_l = -1;
    if (f->m98_reader.read)
        return f->m98_reader.read(f->m98_reader.ctx, b, skipping, &f->m98_p, &f->m98_l, d);
    int has_p = 0;
    double p = 0.0, v;
    for (unsigned k = 0; k < b->n_words && k < NCP_BLOCK_MAX_WORDS; k++) {
        const struct ncp_word *w = &b->words[k];
        if (w->letter != 'P' && w->letter != 'L')
            continue;
        int rc = ncp_flow_eval(f, b, &w->v, &v, d);
        if (rc != NCP_OK)
            return rc;
        if (w->letter == 'P') {
            has_p = 1;
            p = v;
        } else {
            f->m98_l = ncp_trunc_int_round(v);
        }
    }
    if (!has_p)
        return ncp_flow_oword_error(b, "Found 'm98' code with no P-word", d);
    if (ncp_rs274_int(p, &f->m98_p) != 0)
        return ncp_flow_oword_error(b, "Non integer value for integer", d);
    return NCP_OK;
}

/* The label of a loop's opening line (repeat, while): saved the first time it is
 * reached; an error when the name already labels another line, except the `do`
 * that a while line may close (closes_do). */
static int ncp_flow_loop_label(struct ncp_flow *f, const struct ncp_block *b, int closes_do,
                      struct flow_label **out, struct ncp_diag *d)
{
    struct flow_label *op = ncp_flow_find_label(f);
    if (op && !(closes_do && op->type == NCP_O_DO) && op->line != b->line) {
        const char *s;
        int n = ncp_flow_line_text(f, b, &s);
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                            "duplicate O-word label: '%.*s' - defined in line %u", n, s,
                            op->line);
    }
    *out = op;
    return op ? NCP_OK : ncp_flow_save_label(f, b, out, d);
}

/* ======================================================================
 * Loop ends: a skip meets a nested loop it has gone through before and
 * passes it in one step, so that N nested loops cost N steps, not N * N.
 * ====================================================================== */

static void ncp_flow_scan_start(struct ncp_flow *f, struct flow_label *op)
{
    f->scan = (struct flow_scan){ .on = 1, .epoch = f->labels.epoch, .op = op,
                                  .open = f->scan.open, .open_cap = f->scan.open_cap,
                                  .arena = f->scan.arena, .acap = f->scan.acap };
}

static int ncp_flow_scan_push(struct flow_scan *sc, const char *label, size_t len, int kind)
{
    if (sc->n_open == sc->open_cap) {
        uint32_t ncap = sc->open_cap ? sc->open_cap * 2 : 64;
        void *no = realloc(sc->open, ncap * sizeof *sc->open);
        if (!no)
            return -1;
        sc->open = no;
        sc->open_cap = ncap;
    }
    if (sc->used + len > sc->acap) {
        size_t ncap = sc->acap ? sc->acap * 2 : 4096;
        while (ncap < sc->used + len)
            ncap *= 2;
        char *na = realloc(sc->arena, ncap);
        if (!na)
            return -1;
        sc->arena = na;
        sc->acap = ncap;
    }
    memcpy(sc->arena + sc->used, label, len);
    sc->open[sc->n_open].off = (uint32_t)sc->used;
    sc->open[sc->n_open].len = (uint32_t)len;
    sc->open[sc->n_open].kind = (uint8_t)kind;
    sc->n_open++;
    sc->used += len;
    return 0;
}

/* Whether open entry k (from the bottom) has the current label, of one of the kinds. */
static int ncp_flow_scan_is(const struct ncp_flow *f, uint32_t k, int kind1, int kind2)
{
    const struct flow_scan *sc = &f->scan;
    return (sc->open[k].kind == kind1 || sc->open[k].kind == kind2) &&
           sc->open[k].len == f->label_len &&
           memcmp(sc->arena + sc->open[k].off, f->label, f->label_len) == 0;
}

static int ncp_flow_scan_pop(struct ncp_flow *f, int kind)
{
    struct flow_scan *sc = &f->scan;
    if (!sc->n_open || !ncp_flow_scan_is(f, sc->n_open - 1, kind, kind))
        return 0;
    sc->n_open--;
    sc->used = sc->open[sc->n_open].off;
    return 1;
}

/* An O-word line of another label met by the scan: 0 when the loop's text
 * is not one a skip passes unchanged. An opening line must be its label's
 * only line in the table, so no label skipped to later hides in the loop. */
static int ncp_flow_scan_other(struct ncp_flow *f, const struct ncp_block *b)
{
    struct flow_scan *sc = &f->scan;
    int kind = b->oword.kind;
    switch (kind) {
    case NCP_O_CALL:                  /* a skip ignores calls */
        return 1;
    case NCP_O_WHILE:
        if (ncp_flow_scan_pop(f, NCP_O_DO))
            return 1;
        /* fall through */ /* a while loop's head */
    case NCP_O_DO:
    case NCP_O_REPEAT:
    case NCP_O_IF: {
        const struct flow_label *op = ncp_flow_find_label(f);
        if (op && (op->off != b->offset || op->file != f->cur.file))
            return 0;
        return ncp_flow_scan_push(sc, f->label, f->label_len, kind) == 0;
    }
    case NCP_O_ENDWHILE:
        return ncp_flow_scan_pop(f, NCP_O_WHILE);
    case NCP_O_ENDREPEAT:
        return ncp_flow_scan_pop(f, NCP_O_REPEAT);
    case NCP_O_ENDIF:
        return ncp_flow_scan_pop(f, NCP_O_IF);
    case NCP_O_ELSE:
    case NCP_O_ELSEIF:
        return sc->n_open && ncp_flow_scan_is(f, sc->n_open - 1, NCP_O_IF, NCP_O_IF);
    case NCP_O_BREAK:
    case NCP_O_CONTINUE:
        /* of a loop opened in this one (looked for a few levels up only) */
        for (uint32_t k = sc->n_open, seen = 0; k > 0 && seen < 16; k--, seen++)
            if (ncp_flow_scan_is(f, k - 1, NCP_O_WHILE, NCP_O_DO))
                return 1;
        return 0;
    default:                          /* subs, M98/M99: a skip reads them */
        return 0;
    }
}

/* The line the skip was going to: a loop's end line reached with nothing in
 * between that a skip notices is where any later skip can pass it by. */
static void ncp_flow_scan_end(struct ncp_flow *f, const struct ncp_block *b)
{
    struct flow_scan *sc = &f->scan;
    sc->on = 0;
    int want = sc->op->type == NCP_O_REPEAT ? NCP_O_ENDREPEAT : NCP_O_ENDWHILE;
    if (sc->n_open || b->oword.kind != want)
        return;
    sc->op->end_next = f->cur.off;
    sc->op->end_next_line = f->cur.line;
    sc->op->region_epoch = sc->epoch;
}

/* Skipping to another label, at the head of a loop whose end is known: go
 * past that end. The label skipped to must be known outside the loop: each
 * label in the loop was unknown, or known at its own line there, when the
 * end was learnt, and none has been added since. 1 when it went past. */
static int ncp_flow_pass_loop(struct ncp_flow *f, const struct ncp_block *b)
{
    const struct flow_label *op = ncp_flow_find_label(f);
    if (!op || !op->end_next || op->region_epoch != f->labels.epoch ||
        op->off != b->offset || op->file != f->cur.file || op->type != b->oword.kind)
        return 0;
    const struct flow_label *to = ncp_flow_labels_find(&f->labels, f->skip.s, f->skip.len);
    if (!to || (to->file == op->file && to->off >= op->off && to->off < op->end_next))
        return 0;
    ncp_flow_go_to(f, (struct flow_pos){ op->end_next, op->end_next_line, op->file });
    return 1;
}

/* An O-word line read while skipping: 1 when it was a loop passed by. */
static int ncp_flow_skipped_oword(struct ncp_flow *f, const struct ncp_block *b)
{
    int other = !ncp_flow_name_eq(&f->skip, f->label, f->label_len);
    int kind = b->oword.kind;
    if (other && (kind == NCP_O_WHILE || kind == NCP_O_REPEAT) && ncp_flow_pass_loop(f, b))
        return 1;
    if (!f->scan.on)
        return 0;
    if (f->scan.epoch != f->labels.epoch || (other && !ncp_flow_scan_other(f, b)))
        f->scan.on = 0;
    else if (!other)
        ncp_flow_scan_end(f, b);
    return 0;
}

static int ncp_flow_do_repeat(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    struct flow_label *op = NULL;
    int rc = ncp_flow_loop_label(f, b, 0, &op, d);
    if (rc != NCP_OK || !op) /* op is set whenever rc is NCP_OK */
        return rc;
    f->skip.on = 0;
    if (op->type != NCP_O_REPEAT)
        return NCP_OK;
    if (op->repeat_count == -1) {
        double r = floor(f->test_value + 0.5);
        op->repeat_count = r > INT32_MAX ? INT32_MAX : r < 0 ? 0 : (int32_t)r;
    }
    ncp_flow_loop_entered(f, op);
    if (op->repeat_count > 0) {
        op->repeat_count--;
        return ncp_flow_count_iteration(f, b, op, d);
    }
    ncp_flow_skip_to_label(f, b);
    ncp_flow_scan_start(f, op);
    op->repeat_count = -1;
    return ncp_flow_count_idle_lap(f, b, op, d);
}

static int ncp_flow_do_while(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    struct flow_label *op = NULL;
    int rc = ncp_flow_loop_label(f, b, 1, &op, d);
    if (rc != NCP_OK || !op) /* op is set whenever rc is NCP_OK */
        return rc;
    f->skip.on = 0;
    if (op->type == NCP_O_WHILE) {
        ncp_flow_loop_entered(f, op);
        if (f->test_value != 0.0)
            return ncp_flow_count_iteration(f, b, op, d);
        ncp_flow_skip_to_label(f, b);
        ncp_flow_scan_start(f, op);
        return ncp_flow_count_idle_lap(f, b, op, d);
    }
    /* the closing line of a do/while loop */
    if (f->test_value != 0.0 && !f->doing_break) {
        rc = ncp_flow_count_iteration(f, b, op, d);
        if (rc == NCP_OK)
            ncp_flow_jump_to(f, op);
        return rc;
    }
    f->doing_break = 0;
    return NCP_OK;
}

static int ncp_flow_do_do(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    struct flow_label *op = ncp_flow_find_label(f);
    f->skip.on = 0;
    if (!op)
        return ncp_flow_save_label(f, b, NULL, d);
    ncp_flow_loop_entered(f, op);
    return NCP_OK;
}

static int ncp_flow_do_if(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    const struct flow_label *op = ncp_flow_find_label(f);
    if (op && op->line != b->line) {
        const char *s;
        int n = ncp_flow_line_text(f, b, &s);
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                            "duplicate O-word label - already defined in line %u: '%.*s'",
                            op->line, n, s);
    }
    if (!op) {
        int rc = ncp_flow_save_label(f, b, NULL, d);
        if (rc != NCP_OK)
            return rc;
    }
    if (f->test_value != 0.0) {
        f->skip.on = 0;
        f->executed_if = 1;
    } else {
        ncp_flow_skip_to_label(f, b);
        f->executed_if = 0;
    }
    return NCP_OK;
}

/* elseif / else: the label must be an if's. */
static int ncp_flow_do_else(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    const struct flow_label *op = ncp_flow_find_label(f);
    if (!op)
        return ncp_flow_err_undefined(f, b, d);
    if (op->type != NCP_O_IF)
        return ncp_flow_err_mismatch(f, b, "no matching 'if' label", op, d);
    if (f->executed_if) {
        ncp_flow_skip_to_label(f, b);
        return NCP_OK;
    }
    if (b->oword.kind == NCP_O_ELSEIF) {
        if (f->test_value != 0.0) {
            f->skip.on = 0;
            f->executed_if = 1;
        }
    } else if (ncp_flow_name_eq(&f->skip, f->label, f->label_len)) {
        f->executed_if = 1;
        f->skip.on = 0;
    }
    return NCP_OK;
}

static int ncp_flow_do_endif(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    const struct flow_label *op = ncp_flow_find_label(f);
    if (!op)
        return ncp_flow_err_undefined(f, b, d);
    if (op->type != NCP_O_IF) {
        const char *s;
        int n = ncp_flow_line_text(f, b, &s);
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.col,
                            "no matching label: '%s' (found '%s' in line %u): '%.*s'",
                            f->label, ncp_flow_kind_name(op->type), op->line, n, s);
    }
    f->skip.on = 0;
    f->executed_if = 1;
    return NCP_OK;
}

/* break / continue: the label must be a while's or a do's. */
static int ncp_flow_do_break(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    const struct flow_label *op = ncp_flow_find_label(f);
    if (!op)
        return ncp_flow_err_undefined(f, b, d);
    if (op->type != NCP_O_WHILE && op->type != NCP_O_DO)
        return ncp_flow_err_mismatch(f, b, "no matching while/do label", op, d);
    if (b->oword.kind == NCP_O_BREAK) {
        f->doing_break = 1;
    } else {
        if (ncp_flow_name_eq(&f->skip, f->label, f->label_len))
            return NCP_OK;
        f->doing_continue = 1;
    }
    ncp_flow_skip_to_label(f, b);
    return NCP_OK;
}

static int ncp_flow_do_endloop(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    struct flow_label *op = ncp_flow_find_label(f);
    if (!op)
        return ncp_flow_err_undefined(f, b, d);
    int want = b->oword.kind == NCP_O_ENDREPEAT ? NCP_O_REPEAT : NCP_O_WHILE;
    if (op->type != want)
        return ncp_flow_err_mismatch(f, b, "no matching label", op, d);
    if (ncp_flow_name_eq(&f->skip, f->label, f->label_len)) {
        f->skip.on = 0;
        if (!f->doing_continue)
            return NCP_OK;
        f->doing_continue = 0;
    }
    ncp_flow_jump_to(f, op);
    return NCP_OK;
}

/* An O number computed from parameters ("o#1 call", "o[#1+1] sub"): rs274
 * reads it whenever it reads the line, skipping or not, so a label's name is
 * the value its parameters have then; inside a sub being defined an undefined
 * named parameter reads as 0, as everywhere there. */
static int ncp_flow_read_number(struct ncp_flow *f, const struct ncp_block *b,
                                struct ncp_diag *d)
{
    double v;
    int n;
    int rc = f->defining.on && f->level == 0 ? ncp_flow_eval_lenient(f, b, &b->oword.num, &v, d)
                                              : ncp_flow_eval(f, b, &b->oword.num, &v, d);
    if (rc != NCP_OK)
        return rc;
    if (ncp_rs274_int(v, &n) != 0)
        return ncp_flow_oword_error(b, "Non integer value for integer", d);
    snprintf(f->number, sizeof f->number, "%d", n);
    return NCP_OK;
}

static int ncp_flow_run_oword(struct ncp_flow *f, const struct ncp_block *b, struct ncp_diag *d)
{
    int ignore;
    if (b->oword.kind == NCP_O_M98) {
        int rc = ncp_flow_read_m98(f, b, f->skip.on, d);
        if (rc != NCP_OK)
            return rc;
    }
    if (b->oword.name_computed) {
        int rc = ncp_flow_read_number(f, b, d);
        if (rc != NCP_OK)
            return rc;
    }
    ncp_flow_make_label(f, b);
    if (f->skip.on && ncp_flow_skipped_oword(f, b))
        return NCP_OK;
    int rc = ncp_flow_read_oword(f, b, &ignore, d);
    if (rc != NCP_OK || ignore || ncp_flow_skipping_other(f))
        return rc;
    if (f->seek_sub.on && b->oword.kind != NCP_O_SUB && b->oword.kind != NCP_O_FANUC)
        return NCP_OK;
    switch (b->oword.kind) {
    case NCP_O_SUB:
        return ncp_flow_do_sub(f, b, d);
    case NCP_O_FANUC:
        return ncp_flow_do_fanuc(f, b, d);
    case NCP_O_ENDSUB:
    case NCP_O_RETURN:
    case NCP_O_M99:
        return ncp_flow_do_return(f, b, d);
    case NCP_O_CALL:
        return ncp_flow_do_call(f, b, d);
    case NCP_O_M98:
        return ncp_flow_do_m98(f, b, d);
    case NCP_O_DO:
        return ncp_flow_do_do(f, b, d);
    case NCP_O_REPEAT:
        return ncp_flow_do_repeat(f, b, d);
    case NCP_O_WHILE:
        return ncp_flow_do_while(f, b, d);
    case NCP_O_IF:
        return ncp_flow_do_if(f, b, d);
    case NCP_O_ELSEIF:
    case NCP_O_ELSE:
        return ncp_flow_do_else(f, b, d);
    case NCP_O_ENDIF:
        return ncp_flow_do_endif(f, b, d);
    case NCP_O_BREAK:
    case NCP_O_CONTINUE:
        return ncp_flow_do_break(f, b, d);
    case NCP_O_ENDWHILE:
    case NCP_O_ENDREPEAT:
        return ncp_flow_do_endloop(f, b, d);
    default:
        return ncp_flow_oword_error(b, "Unknown command in O-word line", d);
    }
}

/* End of the program body while still looking for a label. */
static int ncp_flow_at_end(struct ncp_flow *f, struct ncp_diag *d)
{
    if (f->skip.on && f->src->has_percent) {
        f->ended_at_percent = 1;
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, f->cur.line, 0,
                            "Failed to find sub 'O%s' before EOF", f->skip.s);
    }
    if (f->seek_sub.on) {
        /* the error is at the call, in the file that holds it */
        uint32_t file = f->cur.file;
        f->cur.file = f->seek_call.file;
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, f->seek_call.line, f->seek_call_col,
                            "EOF in file:%s seeking o-word: o<%s> from line: %u",
                            ncp_flow_file_name(f, file), f->seek_sub.s, f->skip_start);
    }
    /* a subroutine file read to its end without endsub or return: the
     * program has no end either */
    if (f->cur.file != 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, f->cur.line > 1 ? f->cur.line - 1 : 1, 0,
                            "File ended with no percent sign or program end");
    return NCP_END;
}

/* A line that starts with an M whose value comes from parameters ("M#1"):
 * rs274 reads that value as it reads the line, skipping or not, and a 98, or
 * a 99 inside a sub, makes the line a Fanuc call or return, read again as
 * such; any other value, or one it cannot read, an ordinary line. Sets *kind,
 * and *b to the block to go on with (the line read again, or as it was). */
static int ncp_flow_resolve_m_value(struct ncp_flow *f, const struct ncp_block **b, int *kind,
                           struct ncp_diag *d)
{
    const struct ncp_block *blk = *b;
    *kind = NCP_O_NONE;
    if (blk->n_words == 0 || blk->words[0].letter != 'M')
        return NCP_OK;
    double v;
    int m;
    struct ncp_diag unread;
    if (ncp_flow_eval(f, blk, &blk->words[0].v, &v, &unread) != NCP_OK ||
        ncp_rs274_int(v, &m) != 0 || !(m == NCP_M98 || (m == NCP_M99 && f->level > 0)))
        return NCP_OK;
    if (!f->fanuc_blk && !(f->fanuc_blk = malloc(sizeof *f->fanuc_blk)))
        return ncp_diag_set(d, NCP_ERR_IO, blk->line, 0, "out of memory");
    if (ncp_blocks_relex_fanuc(f->src, blk, m, f->fanuc_blk) != 0)
        return NCP_OK;
    *b = f->fanuc_blk;
    *kind = f->fanuc_blk->oword.kind;
    return NCP_OK;
}

static int ncp_flow_step(struct ncp_flow *f, const struct ncp_block **out,
                     struct ncp_diag *d)
{
    for (;;) {
        int skipping = f->skip.on;
        const struct ncp_block *b = NULL;
        uint64_t target = f->jump_target;
        f->jump_target = UINT64_MAX;
        int rc = ncp_flow_fetch(f, skipping, &b, d);
        if (rc == NCP_END)
            return ncp_flow_at_end(f, d);
        if (rc != NCP_OK)
            return rc;
        if (!b)
            continue;
        if (f->cancel && (++f->ticks & (CANCEL_BLOCKS - 1)) == 0 &&
            (rc = ncp_flow_cancelled(f, b, d)) != NCP_OK)
            return rc;
        if (FLOW_BLOCK_DELETE && b->block_delete)
            continue;
        f->by_jump = b->offset == target;
        int kind = b->oword.kind;
        if (kind != NCP_O_NONE) { /* one test on the plain path for the rare kinds */
            if (kind == NCP_O_M_VALUE && (rc = ncp_flow_resolve_m_value(f, &b, &kind, d)) != NCP_OK)
                return rc;
            /* M99 first on a line returns from a sub; in the main program it
             * is an M code like M2 */
            if (kind == NCP_O_M99 && f->level == 0)
                kind = NCP_O_NONE;
            if (f->no_fanuc && (rc = ncp_flow_no_fanuc(b, kind, d)) != NCP_OK)
                return rc;
        }
        if (b->err.code != NCP_OK) {
            /* rs274 does not parse the lines it skips, but for M98 lines;
             * the rest of an M99 line in a sub, only comments are allowed */
            if (skipping && kind != NCP_O_M98)
                continue;
            if (kind == NCP_O_M99 && b->oword.tail_col)
                return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, b->oword.tail_col,
                                    "Unexpected character after O-word");
            /* a G7x profile: the caller reads it its way; a plain line: the
             * caller reports the faults left of the lexer's first */
            if (f->inline_level >= 0 || kind == NCP_O_NONE) {
                *out = b;
                return NCP_OK;
            }
            *d = b->err;
            return b->err.code;
        }
        if (kind == NCP_O_NONE) {
            if (skipping)
                continue;
            *out = b;
            return NCP_OK;
        }
        rc = ncp_flow_run_oword(f, b, d);
        if (rc != NCP_OK)
            return rc;
        if (f->inline_level >= 0 && f->level == f->inline_level) {
            /* a remap's sub may run inside another's */
            f->inline_level = f->frames[f->level + 1].inline_prev;
            *out = b;
            return NCP_FLOW_RETURNED;
        }
    }
}

int ncp_flow_call_inline(struct ncp_flow *f, const struct ncp_block *call,
                         struct ncp_diag *d)
{
    int level = f->level, prev = f->inline_level;
    int rc = ncp_flow_run_oword(f, call, d);
    if (rc == NCP_OK) {
        if (f->level > level)
            f->frames[level + 1].inline_prev = prev;
        f->inline_level = level;
    }
    return rc;
}

int ncp_flow_next(struct ncp_flow *f, const struct ncp_block **out, struct ncp_diag *d)
{
    int rc = ncp_flow_step(f, out, d);
    /* no block goes out with an end or an error: hand the last one back now,
     * while the feed surely still exists */
    if (rc != NCP_OK && rc != NCP_FLOW_RETURNED)
        ncp_flow_release_feed(f);
    return rc;
}

/* ======================================================================
 * Life cycle
 * ====================================================================== */

struct ncp_flow *ncp_flow_new(const struct ncp_block_feed *feed, struct ncp_params *params,
                              const struct ncp_analyzer_cfg *cfg)
{
    struct ncp_flow *f = calloc(1, sizeof *f);
    if (!f)
        return NULL;
    f->feed = *feed;
    f->src = f->prog = feed->src;
    f->sub_path = cfg ? cfg->subroutine_path : NULL;
    f->params = params;
    f->pops = ncp_params_ops(params);
    f->max_loops = cfg && cfg->max_loop_iterations ? cfg->max_loop_iterations
                                                   : NCP_DEFAULT_MAX_LOOPS;
    f->max_depth = cfg && cfg->max_call_depth ? cfg->max_call_depth : FLOW_DEFAULT_MAX_DEPTH;
    f->oword_nargs = cfg ? cfg->oword_nargs : 0;
    f->no_fanuc = cfg ? cfg->no_fanuc_subs : 0;
    f->cancel = cfg ? cfg->cancel : NULL;
    f->cancel_ctx = cfg ? cfg->cancel_ctx : NULL;
    f->cur.off = f->src->begin;
    f->cur.line = f->src->begin_line;
    f->feed_pos = f->cur;
    f->jump_target = UINT64_MAX;
    f->inline_level = -1;
    if (ncp_flow_grow_frames(f) != 0) {
        free(f);
        return NULL;
    }
    memset(&f->frames[0], 0, sizeof f->frames[0]);
    f->frames[0].m98_loops = -1;
    return f;
}

void ncp_flow_set_param_ops(struct ncp_flow *f, struct ncp_param_ops ops)
{
    f->pops = ops;
}

void ncp_flow_set_frame_hooks(struct ncp_flow *f, struct ncp_flow_frames hooks)
{
    f->hooks = hooks;
}

void ncp_flow_set_m98_reader(struct ncp_flow *f, struct ncp_flow_m98_reader r)
{
    f->m98_reader = r;
}

void ncp_flow_free(struct ncp_flow *f)
{
    if (!f)
        return;
    ncp_flow_release_feed(f);
    ncp_sub_files_free(f->files);
    ncp_block_reread_free(f->reread);
    free(f->fanuc_blk);
    free(f->scan.open);
    free(f->scan.arena);
    free(f->labels.slots);
    free(f->labels.arena);
    free(f->frames);
    free(f);
}

const struct ncp_source *ncp_flow_source(const struct ncp_flow *f)
{
    return f->src;
}

const char *ncp_flow_file(const struct ncp_flow *f)
{
    return f->cur.file == 0 ? NULL : ncp_sub_files_name(f->files, f->cur.file);
}

unsigned ncp_flow_file_tag(const struct ncp_flow *f)
{
    return f->cur.file == 0 ? 0 : ncp_sub_files_tag(f->files, f->cur.file);
}

int ncp_flow_ended_at_percent(const struct ncp_flow *f)
{
    return f->ended_at_percent;
}

int ncp_flow_call_depth(const struct ncp_flow *f)
{
    return f->level;
}

void ncp_flow_reset(struct ncp_flow *f)
{
    while (f->level > 0) {
        ncp_params_pop_call(f->params);
        f->level--;
    }
    f->skip.on = 0;
    f->scan.on = 0;
    f->seek_sub.on = 0;
    f->defining.on = 0;
    f->in_sub_context = 0;
    f->inline_level = -1;
    f->frames[0].m98_loops = -1;
    ncp_flow_labels_clear(&f->labels);
}
