/* Parameter store: numbered range, named locals/globals, call scopes, the
 * predefined-name hook and rs274's error wording. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "../../src/analyzer/params.h"

#define NAME(s) (s), strlen(s)

static int setup(void **state)
{
    *state = ncp_params_new();
    return *state ? 0 : -1;
}

static int teardown(void **state)
{
    ncp_params_free(*state);
    return 0;
}

static void test_numbered_start_values(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v = -1;
    for (int i = 1; i < NCP_PARAMS_MAX; i++) {
        assert_int_equal(ncp_params_get(p, i, &v, &d), NCP_OK);
        /* rs274 starts in G54: #5220 = 1, everything else 0 */
        assert_true(v == (i == 5220 ? 1.0 : 0.0));
    }
}

static void test_numbered_range(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    assert_int_equal(ncp_params_set(p, 5601, 7.5, &d), NCP_OK);
    assert_int_equal(ncp_params_get(p, 5601, &v, &d), NCP_OK);
    assert_true(v == 7.5);
    assert_int_equal(ncp_params_get(p, 0, &v, &d), NCP_ERR_SEMANTIC);
    assert_string_equal(d.msg, "Parameter number out of range");
    assert_int_equal(ncp_params_get(p, 5602, &v, &d), NCP_ERR_SEMANTIC);
    assert_int_equal(ncp_params_set(p, 0, 1, &d), NCP_ERR_SEMANTIC);
    assert_int_equal(ncp_params_set(p, -3, 1, &d), NCP_ERR_SEMANTIC);
    assert_int_equal(ncp_params_set(p, 100000, 1, &d), NCP_ERR_SEMANTIC);
    *ncp_params_slot(p, 5420) = 3.25;
    assert_int_equal(ncp_params_get(p, 5420, &v, &d), NCP_OK);
    assert_true(v == 3.25);
    /* out-of-range raw access must not write out of bounds */
    *ncp_params_slot(p, 99999) = 1.0;
}

static void test_named_locals_and_globals(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    assert_int_equal(ncp_params_get_named(p, NAME("foo"), &v, &d), NCP_ERR_SEMANTIC);
    assert_string_equal(d.msg, "Named parameter #<foo> not defined");
    assert_int_equal(ncp_params_get_named(p, NAME("_foo"), &v, &d), NCP_ERR_SEMANTIC);
    assert_string_equal(d.msg, "Named parameter #<_foo> not defined");
    assert_false(ncp_params_exists(p, NAME("foo")));

    assert_int_equal(ncp_params_set_named(p, NAME("foo"), 1.5, &d), NCP_OK);
    assert_int_equal(ncp_params_set_named(p, NAME("_g"), 2.5, &d), NCP_OK);
    assert_true(ncp_params_exists(p, NAME("foo")));
    assert_true(ncp_params_exists(p, NAME("_g")));
    assert_int_equal(ncp_params_get_named(p, NAME("foo"), &v, &d), NCP_OK);
    assert_true(v == 1.5);
    assert_int_equal(ncp_params_set_named(p, NAME("foo"), 4.0, &d), NCP_OK);
    assert_int_equal(ncp_params_get_named(p, NAME("foo"), &v, &d), NCP_OK);
    assert_true(v == 4.0);

    /* a subroutine sees the globals but not its caller's locals */
    double args[2] = { 5, 6 };
    assert_int_equal(ncp_params_push_call(p, args, 2, &d), NCP_OK);
    assert_int_equal(ncp_params_call_level(p), 1);
    assert_false(ncp_params_exists(p, NAME("foo")));
    assert_int_equal(ncp_params_get_named(p, NAME("_g"), &v, &d), NCP_OK);
    assert_true(v == 2.5);
    assert_int_equal(ncp_params_set_named(p, NAME("bar"), 9, &d), NCP_OK);
    assert_int_equal(ncp_params_set_named(p, NAME("_g"), 3.5, &d), NCP_OK);
    ncp_params_pop_call(p);
    assert_int_equal(ncp_params_call_level(p), 0);
    assert_false(ncp_params_exists(p, NAME("bar")));
    assert_int_equal(ncp_params_get_named(p, NAME("foo"), &v, &d), NCP_OK);
    assert_true(v == 4.0);
    assert_int_equal(ncp_params_get_named(p, NAME("_g"), &v, &d), NCP_OK);
    assert_true(v == 3.5);

    /* the next call at the same level starts with no locals */
    assert_int_equal(ncp_params_push_call(p, NULL, 0, &d), NCP_OK);
    assert_false(ncp_params_exists(p, NAME("bar")));
    ncp_params_pop_call(p);
    ncp_params_pop_call(p); /* extra pop at level 0 is harmless */
    assert_int_equal(ncp_params_call_level(p), 0);
}

static void test_declare(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    assert_int_equal(ncp_params_declare_named(p, NAME("y"), &d), NCP_OK);
    assert_true(ncp_params_exists(p, NAME("y")));
    assert_int_equal(ncp_params_get_named(p, NAME("y"), &v, &d), NCP_OK);
    assert_true(v == 0);
    assert_int_equal(ncp_params_set_named(p, NAME("y"), 5, &d), NCP_OK);
    assert_int_equal(ncp_params_declare_named(p, NAME("y"), &d), NCP_OK);
    assert_int_equal(ncp_params_get_named(p, NAME("y"), &v, &d), NCP_OK);
    assert_true(v == 5);
    /* read-only names are left alone (the assignment itself fails) */
    assert_int_equal(ncp_params_declare_named(p, NAME("_value"), &d), NCP_OK);
    assert_int_equal(ncp_params_declare_named(p, NAME("_g"), &d), NCP_OK);
    assert_true(ncp_params_exists(p, NAME("_g")));
    /* locals are declared in the current call's scope */
    assert_int_equal(ncp_params_push_call(p, NULL, 0, &d), NCP_OK);
    assert_int_equal(ncp_params_declare_named(p, NAME("y"), &d), NCP_OK);
    assert_int_equal(ncp_params_get_named(p, NAME("y"), &v, &d), NCP_OK);
    assert_true(v == 0);
    ncp_params_pop_call(p);
    assert_int_equal(ncp_params_get_named(p, NAME("y"), &v, &d), NCP_OK);
    assert_true(v == 5);
}

static void test_many_names(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    char name[32];
    double v;
    for (int i = 0; i < 5000; i++) {
        int n = snprintf(name, sizeof name, "%sn%d", i % 2 ? "_" : "", i);
        assert_int_equal(ncp_params_set_named(p, name, (size_t)n, i, &d), NCP_OK);
    }
    for (int i = 0; i < 5000; i++) {
        int n = snprintf(name, sizeof name, "%sn%d", i % 2 ? "_" : "", i);
        assert_int_equal(ncp_params_get_named(p, name, (size_t)n, &v, &d), NCP_OK);
        assert_true(v == i);
    }
}

static void test_call_args(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v, args[3] = { 1, 2, 3 };
    for (int i = 1; i <= 31; i++)
        assert_int_equal(ncp_params_set(p, i, 100 + i, &d), NCP_OK);
    assert_int_equal(ncp_params_push_call(p, args, 3, &d), NCP_OK);
    for (int i = 1; i <= 31; i++) {
        assert_int_equal(ncp_params_get(p, i, &v, &d), NCP_OK);
        double want = i <= 3 ? i : i <= NCP_CALL_ARGS ? 0 : 100 + i;
        assert_true(v == want);
    }
    assert_int_equal(ncp_params_set(p, 2, 42, &d), NCP_OK);
    assert_int_equal(ncp_params_push_call(p, NULL, 0, &d), NCP_OK);
    assert_int_equal(ncp_params_get(p, 1, &v, &d), NCP_OK);
    assert_true(v == 0);
    ncp_params_pop_call(p);
    assert_int_equal(ncp_params_get(p, 2, &v, &d), NCP_OK);
    assert_true(v == 42);
    ncp_params_pop_call(p);
    for (int i = 1; i <= 31; i++) {
        assert_int_equal(ncp_params_get(p, i, &v, &d), NCP_OK);
        assert_true(v == 100 + i);
    }
}

static void test_deep_calls(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    for (int i = 0; i < 200; i++) {
        double a = i;
        assert_int_equal(ncp_params_push_call(p, &a, 1, &d), NCP_OK);
        assert_int_equal(ncp_params_set_named(p, NAME("x"), i, &d), NCP_OK);
    }
    for (int i = 199; i >= 0; i--) {
        assert_int_equal(ncp_params_get_named(p, NAME("x"), &v, &d), NCP_OK);
        assert_true(v == i);
        assert_int_equal(ncp_params_get(p, 1, &v, &d), NCP_OK);
        assert_true(v == i);
        ncp_params_pop_call(p);
    }
}

static int fake_predef(void *ctx, const char *name, size_t len, double *out)
{
    (void)ctx;
    if (len == 2 && memcmp(name, "_x", 2) == 0) {
        *out = 12.5;
        return 1;
    }
    return 0;
}

static void test_predefined(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    ncp_params_set_predef(p, fake_predef, NULL);
    assert_int_equal(ncp_params_get_named(p, NAME("_x"), &v, &d), NCP_OK);
    assert_true(v == 12.5);
    assert_true(ncp_params_exists(p, NAME("_x")));
    assert_int_equal(ncp_params_set_named(p, NAME("_x"), 1, &d), NCP_ERR_SEMANTIC);
    assert_string_equal(d.msg, "Cannot assign to read-only parameter #<_x>");

    /* #<_value> and #<_value_returned> start at 0 and are read-only */
    assert_true(ncp_params_exists(p, NAME("_value")));
    assert_int_equal(ncp_params_get_named(p, NAME("_value"), &v, &d), NCP_OK);
    assert_true(v == 0);
    assert_int_equal(ncp_params_set_named(p, NAME("_value"), 1, &d), NCP_ERR_SEMANTIC);
    assert_string_equal(d.msg, "Cannot assign to read-only parameter #<_value>");
    ncp_params_set_return(p, 7, 1);
    assert_int_equal(ncp_params_get_named(p, NAME("_value"), &v, &d), NCP_OK);
    assert_true(v == 7);
    assert_int_equal(ncp_params_get_named(p, NAME("_value_returned"), &v, &d), NCP_OK);
    assert_true(v == 1);
    ncp_params_set_return(p, 0, 0);
    assert_int_equal(ncp_params_get_named(p, NAME("_value_returned"), &v, &d), NCP_OK);
    assert_true(v == 0);
}

static void test_ops_adapter(void **state)
{
    struct ncp_params *p = *state;
    struct ncp_diag d;
    double v;
    struct ncp_param_ops ops = ncp_params_ops(p);
    assert_int_equal(ncp_params_set(p, 10, 3, &d), NCP_OK);
    assert_int_equal(ncp_params_set_named(p, NAME("a"), 4, &d), NCP_OK);
    assert_int_equal(ops.get_numbered(ops.ctx, 10, &v, &d), NCP_OK);
    assert_true(v == 3);
    assert_int_equal(ops.get_named(ops.ctx, NAME("a"), &v, &d), NCP_OK);
    assert_true(v == 4);
    assert_true(ops.exists_named(ops.ctx, NAME("a")));
    assert_false(ops.exists_named(ops.ctx, NAME("b")));
    assert_int_equal(ops.get_numbered(ops.ctx, 0, &v, &d), NCP_ERR_SEMANTIC);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_numbered_start_values, setup, teardown),
        cmocka_unit_test_setup_teardown(test_numbered_range, setup, teardown),
        cmocka_unit_test_setup_teardown(test_named_locals_and_globals, setup, teardown),
        cmocka_unit_test_setup_teardown(test_declare, setup, teardown),
        cmocka_unit_test_setup_teardown(test_many_names, setup, teardown),
        cmocka_unit_test_setup_teardown(test_call_args, setup, teardown),
        cmocka_unit_test_setup_teardown(test_deep_calls, setup, teardown),
        cmocka_unit_test_setup_teardown(test_predefined, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ops_adapter, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
