/* Parameter store of the analyzer (module-internal header).
 * Numbered parameters #1..#5602 (all start at 0, #5161.. etc. as rs274), named
 * globals (#<_name>), named locals (#<name>) scoped per subroutine call level,
 * and read-only predefined names answered by a hook the analyzer core installs. */
#ifndef NCP_ANALYZER_PARAMS_H
#define NCP_ANALYZER_PARAMS_H

#include <stddef.h>
#include "ncpar/diag.h"
#include "ncpar/lex.h"

#define NCP_PARAMS_MAX 5602        /* rs274: RS274NGC_MAX_PARAMETERS */
#define NCP_CALL_ARGS 30           /* #1..#30 are the call arguments */

struct ncp_params;

/* Predefined read-only named parameters (#<_x>, #<_line>, ...): return 1 and set
 * *out if `name` is one, else 0. */
typedef int (*ncp_predef_fn)(void *ctx, const char *name, size_t len, double *out);

struct ncp_params *ncp_params_new(void);
void ncp_params_free(struct ncp_params *p);
void ncp_params_set_predef(struct ncp_params *p, ncp_predef_fn fn, void *ctx);

/* line/col: where to point errors. Out-of-range index, undefined named parameter
 * and writes to read-only names are errors with rs274's wording. */
int ncp_params_get(const struct ncp_params *p, int index, double *out,
                   struct ncp_diag *d);
int ncp_params_set(struct ncp_params *p, int index, double v, struct ncp_diag *d);
/* Raw access for the core to keep #5420.. etc. current (no checks, no errors).
 * In-range indices are one array: index + 1's slot follows index's. */
double *ncp_params_slot(struct ncp_params *p, int index);

int ncp_params_get_named(const struct ncp_params *p, const char *name, size_t len,
                         double *out, struct ncp_diag *d);
int ncp_params_set_named(struct ncp_params *p, const char *name, size_t len,
                         double v, struct ncp_diag *d);
int ncp_params_exists(const struct ncp_params *p, const char *name, size_t len);
/* rs274 creates the target of `#<name> = ...` (value 0, in the scope the name
 * belongs to) as it reads the assignment, before it evaluates the value or
 * anything after it on the line: `#<y>=[#<y>+1]` on an unknown y gives 1, and
 * `#<y>=1 #<z>=[#<y>+1]` gives z = 1. The core calls this for each named
 * assignment target in line order. Existing or predefined names are left alone. */
int ncp_params_declare_named(struct ncp_params *p, const char *name, size_t len,
                             struct ncp_diag *d);

/* #<_value> / #<_value_returned> (read-only to programs): set by the O-word
 * flow on return/endsub, with returned = 0 when no value was given. */
void ncp_params_set_return(struct ncp_params *p, double value, int returned);

/* Subroutine call: save #1..#30 and open a new local-name scope, then set
 * #1..#nargs from args (the rest 0, as rs274). Return restores both. */
int ncp_params_push_call(struct ncp_params *p, const double *args, int nargs,
                         struct ncp_diag *d);
/* An M98 call: a new local-name scope, #1..#30 shared with the caller (rs274
 * neither saves nor sets them); its pop restores only the scope. */
int ncp_params_push_shared(struct ncp_params *p, struct ncp_diag *d);
void ncp_params_pop_call(struct ncp_params *p);
/* [RS274NGC]OWORD_NARGS: the new call level's #<n_args>, the count of its
 * arguments, which the sub may not assign. */
int ncp_params_set_nargs(struct ncp_params *p, int nargs, struct ncp_diag *d);
int ncp_params_call_level(const struct ncp_params *p);

/* Adapter for ncp_expr_eval(). */
struct ncp_param_ops ncp_params_ops(struct ncp_params *p);

#endif
