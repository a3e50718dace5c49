/* Parameter store: numbered parameters in a flat array, named parameters in
 * small open-addressing hash tables whose names live in arenas, so a read or an
 * update of an existing name never allocates. Globals (#<_name>) have one table;
 * locals have one table per call level, emptied when the level returns. */
#include "params.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NAMETAB_MIN_CAP 16u
#define ARENA_MIN_CAP 256u

struct name_slot {
    uint32_t hash;
    uint32_t len;        /* 0 = empty slot */
    uint32_t off;        /* name in the table's arena */
    double value;
};

struct nametab {
    struct name_slot *slots;
    uint32_t cap;        /* power of two */
    uint32_t count;
    char *arena;
    size_t arena_used, arena_cap;
};

struct call_frame {
    double saved[NCP_CALL_ARGS];
    int shared;                /* an M98 call: #1..#30 are the caller's */
};

struct ncp_params {
    double num[NCP_PARAMS_MAX];
    struct nametab globals;
    struct nametab *locals;    /* [0 .. n_levels): one scope per call level */
    int n_levels;
    struct call_frame *frames; /* [0 .. level): #1..#30 of the caller */
    int frames_cap;
    int level;
    double ret_value;          /* #<_value> */
    double ret_flag;           /* #<_value_returned> */
    ncp_predef_fn predef;
    void *predef_ctx;
    double scratch;            /* where ncp_params_slot points for a bad index */
    int nargs;                 /* [RS274NGC]OWORD_NARGS: subs have a read-only #<n_args> */
};

static uint32_t name_hash(const char *s, size_t n)
{
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= 16777619u;
    }
    return h ? h : 1u;
}

static int name_is(const char *s, size_t n, const char *lit)
{
    size_t m = strlen(lit);
    return n == m && memcmp(s, lit, n) == 0;
}

/* ---- hash table ---------------------------------------------------------- */

static struct name_slot *tab_find(const struct nametab *t, const char *name,
                                  size_t len, uint32_t h)
{
    if (!t->cap)
        return NULL;
    uint32_t mask = t->cap - 1;
    for (uint32_t i = h & mask;; i = (i + 1) & mask) {
        struct name_slot *s = &t->slots[i];
        if (!s->len)
            return NULL;
        if (s->hash == h && s->len == len && memcmp(t->arena + s->off, name, len) == 0)
            return s;
    }
}

static int tab_grow(struct nametab *t)
{
    uint32_t ncap = t->cap ? t->cap * 2 : NAMETAB_MIN_CAP;
    struct name_slot *ns = calloc(ncap, sizeof *ns);
    if (!ns)
        return -1;
    for (uint32_t i = 0; i < t->cap; i++) {
        const struct name_slot *s = &t->slots[i];
        if (!s->len)
            continue;
        uint32_t j = s->hash & (ncap - 1);
        while (ns[j].len)
            j = (j + 1) & (ncap - 1);
        ns[j] = *s;
    }
    free(t->slots);
    t->slots = ns;
    t->cap = ncap;
    return 0;
}

static int arena_store(struct nametab *t, const char *name, size_t len, uint32_t *off)
{
    if (t->arena_used + len > t->arena_cap) {
        size_t ncap = t->arena_cap ? t->arena_cap : ARENA_MIN_CAP;
        while (ncap < t->arena_used + len)
            ncap *= 2;
        char *na = realloc(t->arena, ncap);
        if (!na)
            return -1;
        t->arena = na;
        t->arena_cap = ncap;
    }
    if (t->arena_used + len > UINT32_MAX)
        return -1;
    memcpy(t->arena + t->arena_used, name, len);
    *off = (uint32_t)t->arena_used;
    t->arena_used += len;
    return 0;
}

/* Insert or update. Returns 0, or -1 when out of memory. */
static int tab_set(struct nametab *t, const char *name, size_t len, double v)
{
    uint32_t h = name_hash(name, len);
    struct name_slot *s = tab_find(t, name, len, h);
    if (s) {
        s->value = v;
        return 0;
    }
    if (len == 0 || len > UINT32_MAX)
        return -1;
    if ((t->count + 1) * 4 > t->cap * 3 && tab_grow(t) != 0)
        return -1;
    uint32_t off;
    if (arena_store(t, name, len, &off) != 0)
        return -1;
    uint32_t mask = t->cap - 1, i = h & mask;
    while (t->slots[i].len)
        i = (i + 1) & mask;
    t->slots[i] = (struct name_slot){ .hash = h, .len = (uint32_t)len, .off = off,
                                      .value = v };
    t->count++;
    return 0;
}

/* Forget every name but keep the memory for the next call at this level. */
static void tab_clear(struct nametab *t)
{
    if (t->count)
        memset(t->slots, 0, t->cap * sizeof *t->slots);
    t->count = 0;
    t->arena_used = 0;
}

static void tab_free(struct nametab *t)
{
    free(t->slots);
    free(t->arena);
}

/* ---- life cycle ---------------------------------------------------------- */

struct ncp_params *ncp_params_new(void)
{
    struct ncp_params *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    /* rs274 starts with the G54 coordinate system selected */
    p->num[5220] = 1.0;
    return p;
}

void ncp_params_free(struct ncp_params *p)
{
    if (!p)
        return;
    tab_free(&p->globals);
    for (int i = 0; i < p->n_levels; i++)
        tab_free(&p->locals[i]);
    free(p->locals);
    free(p->frames);
    free(p);
}

void ncp_params_set_predef(struct ncp_params *p, ncp_predef_fn fn, void *ctx)
{
    p->predef = fn;
    p->predef_ctx = ctx;
}

void ncp_params_set_return(struct ncp_params *p, double value, int returned)
{
    p->ret_value = value;
    p->ret_flag = returned ? 1.0 : 0.0;
}

/* ---- numbered ------------------------------------------------------------ */

static int check_index(int index, struct ncp_diag *d)
{
    if (index < 1 || index >= NCP_PARAMS_MAX)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0, "Parameter number out of range");
    return NCP_OK;
}

int ncp_params_get(const struct ncp_params *p, int index, double *out,
                   struct ncp_diag *d)
{
    int rc = check_index(index, d);
    if (rc != NCP_OK)
        return rc;
    *out = 0.0;
    *out = p->num[index];
    return NCP_OK;
}

int ncp_params_set(struct ncp_params *p, int index, double v, struct ncp_diag *d)
{
    int rc = check_index(index, d);
    if (rc != NCP_OK)
        return rc;
    p->num[index] = v;
    return NCP_OK;
}

double *ncp_params_slot(struct ncp_params *p, int index)
{
    if (index < 0 || index >= NCP_PARAMS_MAX)
        return &p->scratch; /* this table's own: tables of other threads are apart */
    return &p->num[index];
}

/* ---- named --------------------------------------------------------------- */

static int is_global(const char *name, size_t len)
{
    return len > 0 && name[0] == '_';
}

/* Names answered without a table: ours (#<_value>...) and the core's hook. */
static int predefined(const struct ncp_params *p, const char *name, size_t len,
                      double *out)
{
    if (name_is(name, len, "_value")) {
        *out = p->ret_value;
        return 1;
    }
    if (name_is(name, len, "_value_returned")) {
        *out = p->ret_flag;
        return 1;
    }
    return p->predef && p->predef(p->predef_ctx, name, len, out);
}

static const struct nametab *local_tab(const struct ncp_params *p)
{
    return p->level < p->n_levels ? &p->locals[p->level] : NULL;
}

static int undefined(const char *name, size_t len, struct ncp_diag *d)
{
    int n = len > 100 ? 100 : (int)len;
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0, "Named parameter #<%.*s> not defined",
                        n, name);
}

int ncp_params_get_named(const struct ncp_params *p, const char *name, size_t len,
                         double *out, struct ncp_diag *d)
{
    const struct nametab *t;
    if (is_global(name, len)) {
        if (predefined(p, name, len, out))
            return NCP_OK;
        t = &p->globals;
    } else {
        t = local_tab(p);
    }
    const struct name_slot *s = t ? tab_find(t, name, len, name_hash(name, len)) : NULL;
    if (!s)
        return undefined(name, len, d);
    *out = s->value;
    return NCP_OK;
}

static struct nametab *local_tab_for_write(struct ncp_params *p)
{
    if (p->level >= p->n_levels) {
        int n = p->level + 1;
        struct nametab *nl = realloc(p->locals, (size_t)n * sizeof *nl);
        if (!nl)
            return NULL;
        memset(nl + p->n_levels, 0, (size_t)(n - p->n_levels) * sizeof *nl);
        p->locals = nl;
        p->n_levels = n;
    }
    return &p->locals[p->level];
}

int ncp_params_set_named(struct ncp_params *p, const char *name, size_t len,
                         double v, struct ncp_diag *d)
{
    struct nametab *t;
    int n = len > 100 ? 100 : (int)len;
    if (is_global(name, len)) {
        double dummy;
        if (predefined(p, name, len, &dummy))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "Cannot assign to read-only parameter #<%.*s>", n, name);
        t = &p->globals;
    } else {
        if (p->nargs && p->level > 0 && name_is(name, len, "n_args"))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "Cannot assign to read-only parameter #<n_args>");
        t = local_tab_for_write(p);
    }
    if (!t || tab_set(t, name, len, v) != 0)
        return ncp_diag_set(d, NCP_ERR_LIMIT, 0, 0,
                            "out of memory storing parameter #<%.*s>", n, name);
    return NCP_OK;
}

int ncp_params_set_nargs(struct ncp_params *p, int nargs, struct ncp_diag *d)
{
    struct nametab *t = local_tab_for_write(p);
    p->nargs = 1;
    if (!t || tab_set(t, "n_args", 6, nargs) != 0)
        return ncp_diag_set(d, NCP_ERR_LIMIT, 0, 0, "out of memory storing parameter #<n_args>");
    return NCP_OK;
}

int ncp_params_declare_named(struct ncp_params *p, const char *name, size_t len,
                             struct ncp_diag *d)
{
    if (ncp_params_exists(p, name, len))
        return NCP_OK;
    return ncp_params_set_named(p, name, len, 0.0, d);
}

int ncp_params_exists(const struct ncp_params *p, const char *name, size_t len)
{
    const struct nametab *t;
    if (is_global(name, len)) {
        double dummy;
        if (predefined(p, name, len, &dummy))
            return 1;
        t = &p->globals;
    } else {
        t = local_tab(p);
    }
    return t && tab_find(t, name, len, name_hash(name, len)) != NULL;
}

/* ---- calls --------------------------------------------------------------- */

static int push_frame(struct ncp_params *p, const double *args, int nargs, int shared,
                      struct ncp_diag *d)
{
    if (p->level >= p->frames_cap) {
        int ncap = p->frames_cap ? p->frames_cap * 2 : 16;
        struct call_frame *nf = realloc(p->frames, (size_t)ncap * sizeof *nf);
        if (!nf)
            return ncp_diag_set(d, NCP_ERR_LIMIT, 0, 0,
                                "out of memory entering a subroutine");
        p->frames = nf;
        p->frames_cap = ncap;
    }
    p->frames[p->level].shared = shared;
    if (!shared) {
        if (nargs < 0)
            nargs = 0;
        if (nargs > NCP_CALL_ARGS)
            nargs = NCP_CALL_ARGS;
        memcpy(p->frames[p->level].saved, &p->num[1], sizeof p->frames[0].saved);
        for (int i = 0; i < NCP_CALL_ARGS; i++)
            p->num[1 + i] = i < nargs ? args[i] : 0.0;
    }
    p->level++;
    if (p->level < p->n_levels)
        tab_clear(&p->locals[p->level]);
    return NCP_OK;
}

int ncp_params_push_call(struct ncp_params *p, const double *args, int nargs,
                         struct ncp_diag *d)
{
    return push_frame(p, args, nargs, 0, d);
}

int ncp_params_push_shared(struct ncp_params *p, struct ncp_diag *d)
{
    return push_frame(p, NULL, 0, 1, d);
}

void ncp_params_pop_call(struct ncp_params *p)
{
    if (p->level <= 0)
        return;
    if (p->level < p->n_levels)
        tab_clear(&p->locals[p->level]);
    p->level--;
    if (!p->frames[p->level].shared)
        memcpy(&p->num[1], p->frames[p->level].saved, sizeof p->frames[0].saved);
}

int ncp_params_call_level(const struct ncp_params *p)
{
    return p->level;
}

/* ---- expression adapter -------------------------------------------------- */

static int ops_get_numbered(void *ctx, int index, double *out, struct ncp_diag *d)
{
    return ncp_params_get(ctx, index, out, d);
}

static int ops_get_named(void *ctx, const char *name, size_t len, double *out,
                         struct ncp_diag *d)
{
    return ncp_params_get_named(ctx, name, len, out, d);
}

static int ops_exists(void *ctx, const char *name, size_t len)
{
    return ncp_params_exists(ctx, name, len);
}

struct ncp_param_ops ncp_params_ops(struct ncp_params *p)
{
    return (struct ncp_param_ops){ .ctx = p, .get_numbered = ops_get_numbered,
                                   .get_named = ops_get_named,
                                   .exists_named = ops_exists };
}
