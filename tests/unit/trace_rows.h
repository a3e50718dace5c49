/* Reading back the per-cycle trace of `cnc-run run --trace` (ncp_nck_opts.trace)
 * in the motion tests: one struct row per servo cycle. Include after <cmocka.h>. */
#ifndef NCP_TEST_TRACE_ROWS_H
#define NCP_TEST_TRACE_ROWS_H

#include <stdio.h>
#include <stdlib.h>

struct row {
    double t, cmd[3], act[3], v;
    unsigned line;
};

/* The whole trace in f (rewound first); checks the header names the columns.
 * Caller frees the rows. */
static inline struct row *read_trace(FILE *f, size_t *n)
{
    char buf[512];
    rewind(f);
    assert_non_null(fgets(buf, sizeof buf, f));
    assert_string_equal(buf, "t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v\n");
    size_t cap = 4096;
    struct row *r = malloc(cap * sizeof *r);
    assert_non_null(r);
    *n = 0;
    while (fgets(buf, sizeof buf, f)) {
        if (*n == cap) {
            struct row *bigger = realloc(r, (cap *= 2) * sizeof *r);
            assert_non_null(bigger);
            r = bigger;
        }
        struct row *x = &r[(*n)++];
        assert_int_equal(sscanf(buf, "%lf,%u,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &x->t, &x->line,
                                &x->cmd[0], &x->cmd[1], &x->cmd[2], &x->act[0], &x->act[1],
                                &x->act[2], &x->v),
                         9);
    }
    return r;
}

#endif
