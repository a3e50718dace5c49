/* Who may talk to the panel (src/http/policy.c): Origin, Host and framing,
 * as the server judges each request before anything else. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "ncpar/http.h"

static struct ncp_http_policy policy(const char *addr, const char *origins, const char *hosts)
{
    struct ncp_http_policy p;
    char why[200];
    assert_int_equal(ncp_http_policy_init(&p, addr, 8080, origins, hosts, why, sizeof why), 0);
    return p;
}

/* The verdict on a request with these headers (NULL: absent). */
static int verdict(const struct ncp_http_policy *p, const char *host, const char *origin)
{
    struct ncp_http_head h = { .host = host, .origin = origin, .n_host = host != NULL,
                               .n_origin = origin != NULL };
    char why[300];
    return ncp_http_head_verdict(p, &h, why, sizeof why);
}

static void origin_must_be_the_panels_own(void **state)
{
    (void)state;
    struct ncp_http_policy p = policy("127.0.0.1", NULL, NULL);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://127.0.0.1:8080"), 0);
    assert_int_equal(verdict(&p, "localhost:8080", "http://localhost:8080"), 0);
    assert_int_equal(verdict(&p, "LocalHost:8080", "HTTP://localhost:8080"), 0);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", NULL), 0);    /* curl: the token decides */
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://evil.example.com"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "null"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://127.0.0.1.evil.com:8080"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://127.0.0.1:8081"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "https://127.0.0.1:8080"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://localhost:8080"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://127.0.0.1:8080/"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://user@127.0.0.1:8080"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", ""), 403);
    /* Origin is judged first: a foreign page learns nothing of the Host rules */
    assert_int_equal(verdict(&p, "rebind.example.com:8080", "http://evil.example.com"), 403);
    /* two Origins are no origin */
    struct ncp_http_head two = { .host = "127.0.0.1:8080", .n_host = 1,
                                 .origin = "http://127.0.0.1:8080", .n_origin = 2 };
    char why[300];
    assert_int_equal(ncp_http_head_verdict(&p, &two, why, sizeof why), 403);
}

static void allowed_origins(void **state)
{
    (void)state;
    struct ncp_http_policy p =
        policy("127.0.0.1", "https://hmi.shop.lan, http://cell-2.shop.lan:8000", NULL);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "https://hmi.shop.lan"), 0);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "https://hmi.shop.lan:443"), 0);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://hmi.shop.lan"), 403);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://cell-2.shop.lan:8000"), 0);
    assert_int_equal(verdict(&p, "127.0.0.1:8080", "http://cell-2.shop.lan"), 403);
}

static void host_must_name_the_panel(void **state)
{
    (void)state;
    struct ncp_http_policy p = policy("192.168.7.20", NULL, "panel.shop.lan cnc7:9000");
    assert_int_equal(verdict(&p, "192.168.7.20:8080", NULL), 0);
    assert_int_equal(verdict(&p, "localhost", NULL), 0);
    assert_int_equal(verdict(&p, "[::1]:8080", NULL), 0);
    assert_int_equal(verdict(&p, "panel.shop.lan:8080", NULL), 0);
    assert_int_equal(verdict(&p, "cnc7:9000", NULL), 0);           /* a forwarded port */
    assert_int_equal(verdict(&p, "cnc7:8080", NULL), 421);
    assert_int_equal(verdict(&p, "localhost:8081", NULL), 421);
    assert_int_equal(verdict(&p, "rebind.evil.example.com:8080", NULL), 421);
    assert_int_equal(verdict(&p, "rebind.evil.example.com:8080",
                             "http://rebind.evil.example.com:8080"), 421);
    assert_int_equal(verdict(&p, "192.168.7.20:8080 x", NULL), 421);
    assert_int_equal(verdict(&p, NULL, NULL), 400);
    /* a wildcard bind names no address: the machine's own go in ALLOW_HOST */
    struct ncp_http_policy any = policy("0.0.0.0", NULL, "192.168.7.20");
    assert_int_equal(verdict(&any, "0.0.0.0:8080", NULL), 421);
    assert_int_equal(verdict(&any, "192.168.7.21:8080", NULL), 421);
    assert_int_equal(verdict(&any, "192.168.7.20:8080", NULL), 0);
    assert_int_equal(verdict(&any, "127.0.0.1:8080", NULL), 0);
    struct ncp_http_policy v6 = policy("fd00::5", NULL, NULL);
    assert_int_equal(verdict(&v6, "[FD00::5]:8080", NULL), 0);
}

static void framing_that_two_readers_could_read_differently(void **state)
{
    (void)state;
    struct ncp_http_policy p = policy("127.0.0.1", NULL, NULL);
    char why[300];
    struct ncp_http_head h = { .host = "127.0.0.1:8080", .n_host = 1, .content_length = "6",
                               .n_content_length = 1 };
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 0);
    h.n_content_length = 2;
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 400);
    h.n_content_length = 1;
    h.content_length = "6, 6";
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 400);
    h.content_length = "-1";
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 400);
    h.content_length = "6";
    h.transfer_encoding = "chunked";
    h.n_transfer_encoding = 1;
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 400);
    h.n_content_length = 0;
    h.content_length = NULL;
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 411);
    assert_non_null(strstr(why, "Content-Length"));
    h.n_host = 2;
    assert_int_equal(ncp_http_head_verdict(&p, &h, why, sizeof why), 400);
}

static void ini_lists(void **state)
{
    (void)state;
    char why[200];
    assert_int_equal(ncp_http_allow_list_ok("", 1, why, sizeof why), 0);
    assert_int_equal(ncp_http_allow_list_ok("http://a.b:1, https://c", 1, why, sizeof why), 0);
    assert_int_equal(ncp_http_allow_list_ok("null", 1, why, sizeof why), -1);
    assert_non_null(strstr(why, "null"));
    assert_int_equal(ncp_http_allow_list_ok("http://a.b/panel", 1, why, sizeof why), -1);
    assert_int_equal(ncp_http_allow_list_ok("a.b", 1, why, sizeof why), -1);
    assert_int_equal(ncp_http_allow_list_ok("a.b:8080 [fd00::1]", 0, why, sizeof why), 0);
    assert_int_equal(ncp_http_allow_list_ok("http://a.b", 0, why, sizeof why), -1);
    assert_int_equal(ncp_http_allow_list_ok("a.b:70000", 0, why, sizeof why), -1);
    struct ncp_http_policy p;
    assert_int_equal(ncp_http_policy_init(&p, "127.0.0.1", 8080, "nope", NULL, why, sizeof why),
                     -1);
    assert_non_null(strstr(why, "ALLOW_ORIGIN"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(origin_must_be_the_panels_own),
        cmocka_unit_test(allowed_origins),
        cmocka_unit_test(host_must_name_the_panel),
        cmocka_unit_test(framing_that_two_readers_could_read_differently),
        cmocka_unit_test(ini_lists),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
