/* Working memory (ncpar/mem.h): every size gets at least what it asked for,
 * zeroed and writable to its last byte, page aligned, and given back whole;
 * prefaulted memory on 4 KB pages, the text's room on 2 MB pages from 512 KB
 * up where the kernel offers them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "ncpar/mem.h"

static const size_t sizes[] = { 1, 4095, 4096, 4097, 100000, (size_t)512 << 10,
                                ((size_t)512 << 10) + 1, (size_t)1 << 20,
                                (size_t)2 << 20, ((size_t)2 << 20) + 1, (size_t)5 << 20 };

static void check(const struct ncp_mem *m, size_t asked, int may_be_huge)
{
    assert_non_null(m->p);
    assert_true(m->bytes >= asked);
    const unsigned char *p = m->p;
    for (size_t i = 0; i < m->bytes; i += 997)
        assert_int_equal(p[i], 0);
    assert_int_equal(p[m->bytes - 1], 0);
    memset(m->p, 0xa5, m->bytes); /* all of it ours */
    uintptr_t page = m->huge ? (uintptr_t)2 << 20 : 4096;
    assert_int_equal((uintptr_t)m->p % page, 0);
    assert_int_equal(m->bytes % page, 0);
    int want_huge = may_be_huge && asked >= ((size_t)512 << 10) && ncp_mem_huge_usable();
    assert_int_equal(m->huge, want_huge);
    /* the usable part lies inside the mapping */
    assert_true((const char *)m->p >= (const char *)m->base);
    assert_true((const char *)m->p + m->bytes <= (const char *)m->base + m->base_len);
}

/* every size, from one of the two ways to get memory */
static void each_size(int (*get)(struct ncp_mem *, size_t), int may_be_huge)
{
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        struct ncp_mem m;
        assert_int_equal(get(&m, sizes[i]), 0);
        check(&m, sizes[i], may_be_huge);
        ncp_mem_unmap(&m);
        assert_null(m.p);
        assert_null(m.base);
    }
}

static void test_map(void **state)
{
    (void)state;
    each_size(ncp_mem_map, 0);
}

static void test_reserve_huge(void **state)
{
    (void)state;
    each_size(ncp_mem_reserve_huge, 1);
}

static void test_refused(void **state)
{
    (void)state;
    struct ncp_mem m;
    assert_int_equal(ncp_mem_map(&m, 0), -1);
    assert_null(m.p);
    assert_int_equal(ncp_mem_map(&m, SIZE_MAX), -1);
    assert_null(m.p);
    assert_int_equal(ncp_mem_reserve_huge(&m, SIZE_MAX - 4096), -1);
    assert_int_equal(ncp_mem_reserve_huge(&m, 0), -1);
    ncp_mem_unmap(&m); /* a cleared one: nothing */
    struct ncp_mem zero;
    memset(&zero, 0, sizeof zero);
    ncp_mem_unmap(&zero);
}

int main(void)
{
    printf("transparent huge pages for advised memory: %s\n",
           ncp_mem_huge_usable() ? "yes" : "no (4 KB pages only)");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_map),
        cmocka_unit_test(test_reserve_huge),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
