/* src/http's pure parts: the browser's JSON messages into LCM commands (and
 * everything that must be refused), JSON string output, --http's argument. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/http.h"

static enum ncp_http_req parse(const char *json, ncp_command_t *c, int *unknown, char *why)
{
    return ncp_http_parse_request(json, strlen(json), 0x57000001, c, unknown, why, 128);
}

static void commands_map_onto_the_lcm_type(void **state)
{
    (void)state;
    ncp_command_t c;
    int unknown;
    char why[128];
    assert_int_equal(parse("{\"cmd\": \"jog\", \"axis\": \"X\", \"dir\": -1, \"speed\": 300, "
                           "\"dist\": 0.1, \"seq\": 9}", &c, &unknown, why),
                     NCP_HTTP_REQ_COMMAND);
    assert_int_equal(c.kind, NCP_COMMAND_T_JOG);
    assert_string_equal((char *)c.text, "X");
    assert_int_equal(c.ivalue[0], -1);
    assert_true(c.value[0] == 300.0 && c.value[1] == 0.1);
    assert_int_equal(c.seq, 9);
    assert_int_equal(c.client_id, 0x57000001);

    assert_int_equal(parse("{\"cmd\":\"mdi\",\"text\":\"G0 X10 (\\u00e9\\\"q\\\")\",\"seq\":1}",
                           &c, &unknown, why), NCP_HTTP_REQ_COMMAND);
    assert_string_equal((char *)c.text, "G0 X10 (\xc3\xa9\"q\")");

    assert_int_equal(parse("{\"cmd\":\"override\",\"which\":\"spindle\",\"value\":80,\"seq\":2}",
                           &c, &unknown, why), NCP_HTTP_REQ_COMMAND);
    assert_int_equal(c.kind, NCP_COMMAND_T_OVERRIDE);
    assert_int_equal(c.ivalue[0], 2);
    assert_true(c.value[0] == 80.0);

    assert_int_equal(parse("{\"cmd\":\"home\",\"seq\":3}", &c, &unknown, why),
                     NCP_HTTP_REQ_COMMAND);
    assert_string_equal((char *)c.text, "all");
    assert_int_equal(parse("{\"cmd\":\"step\",\"on\":true,\"seq\":4}", &c, &unknown, why),
                     NCP_HTTP_REQ_COMMAND);
    assert_int_equal(c.ivalue[0], 1);
    /* a keep-alive has no ack, so no seq */
    assert_int_equal(parse("{\"cmd\":\"keepalive\"}", &c, &unknown, why), NCP_HTTP_REQ_COMMAND);
    assert_int_equal(parse(" {\"cmd\":\"preview\"} ", &c, &unknown, why), NCP_HTTP_REQ_PREVIEW);
    assert_int_equal(parse("{\"cmd\":\"list\"}", &c, &unknown, why), NCP_HTTP_REQ_LIST);
    /* the Tools and History tabs' reads: no field names a file */
    assert_int_equal(parse("{\"cmd\":\"tools\"}", &c, &unknown, why), NCP_HTTP_REQ_TOOLS);
    assert_int_equal(parse("{\"cmd\":\"history\"}", &c, &unknown, why), NCP_HTTP_REQ_HISTORY);
    assert_int_equal(parse("{\"cmd\":\"tools\",\"path\":\"/etc/passwd\"}", &c, &unknown, why),
                     NCP_HTTP_REQ_TOOLS);
}

/* The panel telling how many parts of a large answer it has read. */
static void got_names_a_message_and_its_parts(void **state)
{
    (void)state;
    ncp_command_t c;
    int unknown;
    char why[128];
    assert_int_equal(parse("{\"cmd\":\"got\",\"id\":7,\"parts\":3}", &c, &unknown, why),
                     NCP_HTTP_REQ_GOT);
    assert_int_equal(c.ivalue[0], 7);
    assert_int_equal(c.ivalue[1], 3);
    assert_int_equal(parse("{\"cmd\":\"got\",\"id\":7}", &c, &unknown, why), NCP_HTTP_REQ_BAD);
    assert_non_null(strstr(why, "parts"));
    assert_int_equal(parse("{\"cmd\":\"got\",\"id\":0,\"parts\":1}", &c, &unknown, why),
                     NCP_HTTP_REQ_BAD);
    assert_int_equal(parse("{\"cmd\":\"got\",\"id\":1,\"parts\":1.5}", &c, &unknown, why),
                     NCP_HTTP_REQ_BAD);
    assert_int_equal(parse("{\"cmd\":\"got\",\"id\":1,\"parts\":1,\"seq\":4}", &c, &unknown,
                           why), NCP_HTTP_REQ_BAD);
    assert_non_null(strstr(why, "seq"));
}

static void bad_messages_are_refused(void **state)
{
    (void)state;
    static const char *const bad[] = {
        "", "{", "}", "[]", "null", "{\"cmd\":\"run\",\"seq\":1", "{\"cmd\":\"run\",\"seq\":1}x",
        "{\"cmd\":\"run\",\"seq\":1,}", "{'cmd':'run'}", "{\"cmd\":\"run\"}",
        "{\"cmd\":\"run\",\"seq\":0}", "{\"cmd\":\"run\",\"seq\":1.5}",
        "{\"cmd\":\"run\",\"seq\":1e12}", "{\"cmd\":\"run\",\"seq\":\"1\"}",
        "{\"cmd\":\"run\",\"seq\":1,\"seq\":2}", "{\"cmd\":\"run\",\"seq\":1,\"x\":{}}",
        "{\"cmd\":\"run\",\"seq\":1,\"line\":[1]}", "{\"cmd\":\"run\",\"seq\":1,\"speed\":5}",
        "{\"cmd\":\"mdi\",\"text\":\"G0\\u0000\",\"seq\":1}", "{\"cmd\":\"mdi\",\"text\":5,\"seq\":1}",
        "{\"cmd\":\"jog\",\"axis\":\"X\",\"speed\":1e999,\"seq\":1}",
        "{\"cmd\":\"jog\",\"axis\":\"X\",\"speed\":NaN,\"seq\":1}",
        "{\"cmd\":\"override\",\"which\":\"coolant\",\"value\":5,\"seq\":1}",
        "{\"cmd\":\"mdi\",\"text\":\"\\ud800\",\"seq\":1}", "{\"cmd\":\"mdi\",\"text\":\"a\nb\",\"seq\":1}",
        "{\"cmd\":\"shutdown\",\"seq\":1}", "{\"cmd\":\"nonsense\",\"seq\":1}", "{\"cmd\":7}",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ncp_command_t c;
        int unknown;
        char why[128] = "";
        if (parse(bad[i], &c, &unknown, why) != NCP_HTTP_REQ_BAD)
            fail_msg("taken: %s", bad[i]);
        assert_true(why[0] != 0);
    }
    ncp_command_t c;
    int unknown;
    char why[128];
    parse("{\"cmd\":\"shutdown\",\"seq\":1}", &c, &unknown, why);
    assert_int_equal(unknown, 1);
    parse("{\"cmd\":\"run\",\"seq\":1,}", &c, &unknown, why);
    assert_int_equal(unknown, 0);
    /* a text longer than the command's field */
    char big[700];
    int n = snprintf(big, sizeof big, "{\"cmd\":\"mdi\",\"seq\":1,\"text\":\"");
    memset(big + n, 'G', 600);
    snprintf(big + n + 600, sizeof big - (size_t)n - 600, "\"}");
    assert_int_equal(parse(big, &c, &unknown, why), NCP_HTTP_REQ_BAD);
}

static void json_strings_are_escaped(void **state)
{
    (void)state;
    char buf[64];
    size_t len = 0;
    assert_int_equal(ncp_http_json_string(buf, sizeof buf, &len, "a\"b\\c\nd\x01", 8), 0);
    assert_string_equal(buf, "\"a\\\"b\\\\c\\nd\\u0001\"");
    len = 0;
    assert_int_equal(ncp_http_json_string(buf, 8, &len, "0123456789", 10), -1);
    assert_true(len < 8);
}

static void listen_spec(void **state)
{
    (void)state;
    struct ncp_http_opts o;
    struct ncp_diag d;
    memset(&o, 0, sizeof o);
    assert_int_equal(ncp_http_parse_listen("8080", &o, &d), 0);
    assert_string_equal(o.addr, "127.0.0.1");
    assert_int_equal(o.port, 8080);
    assert_int_equal(ncp_http_parse_listen("0.0.0.0:80", &o, &d), 0);
    assert_string_equal(o.addr, "0.0.0.0");
    assert_int_equal(ncp_http_parse_listen("[::1]:9000", &o, &d), 0);
    assert_string_equal(o.addr, "::1");
    assert_int_equal(o.port, 9000);
    static const char *const bad[] = { "", "0", "65536", "x", "localhost:80", ":80",
                                       "1.2.3.4:", "1.2.3.4:80x", "[::1]", "300.1.1.1:80" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        if (ncp_http_parse_listen(bad[i], &o, &d) == 0)
            fail_msg("taken: '%s'", bad[i]);
}

/* Uploaded programs' names: plain names in the program folder, never a path. */
static void upload_names(void **state)
{
    (void)state;
    char why[160];
    static const char *const good[] = { "part1.ngc", "A-b_c+2.NC", "x.tap", "1.ngc" };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
        assert_int_equal(ncp_http_upload_name_ok(good[i], why, sizeof why), 1);
    static const char *const bad[] = { "", "../x.ngc", "dir/x.ngc", "..\\x.ngc", ".hidden.ngc",
                                       "-rf.ngc", "a b.ngc", "x.txt", ".ngc", "x.ngc/",
                                       "caf\xc3\xa9.ngc", "x\n.ngc", "ngc" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        why[0] = 0;
        assert_int_equal(ncp_http_upload_name_ok(bad[i], why, sizeof why), 0);
        assert_true(why[0] != 0);
    }
    char longname[NCP_HTTP_UPLOAD_NAME_MAX + 8];
    memset(longname, 'a', sizeof longname);
    memcpy(longname + NCP_HTTP_UPLOAD_NAME_MAX - 4, ".ngc", 5);
    assert_int_equal(ncp_http_upload_name_ok(longname, why, sizeof why), 1);
    memset(longname, 'a', sizeof longname);
    memcpy(longname + NCP_HTTP_UPLOAD_NAME_MAX - 3, ".ngc", 5);
    assert_int_equal(ncp_http_upload_name_ok(longname, why, sizeof why), 0);
}

/* A name the panel loads or uploads is of the program folder; an absolute
 * path stays itself; no folder keeps the name as it is. */
static void program_folder_paths(void **state)
{
    (void)state;
    char out[32];
    assert_int_equal(ncp_http_program_path("/nc/files", "a.ngc", out, sizeof out), 0);
    assert_string_equal(out, "/nc/files/a.ngc");
    assert_int_equal(ncp_http_program_path("/nc/files/", "a.ngc", out, sizeof out), 0);
    assert_string_equal(out, "/nc/files/a.ngc");
    assert_int_equal(ncp_http_program_path("/nc/files", "/abs/b.ngc", out, sizeof out), 0);
    assert_string_equal(out, "/abs/b.ngc");
    assert_int_equal(ncp_http_program_path(NULL, "c.ngc", out, sizeof out), 0);
    assert_string_equal(out, "c.ngc");
    assert_int_equal(ncp_http_program_path("", "c.ngc", out, sizeof out), 0);
    assert_string_equal(out, "c.ngc");
    /* 31 characters fit, 32 do not */
    assert_int_equal(ncp_http_program_path("/nc/files", "012345678901234567890", out,
                                           sizeof out), 0);
    assert_int_equal(ncp_http_program_path("/nc/files", "0123456789012345678901", out,
                                           sizeof out), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(commands_map_onto_the_lcm_type),
        cmocka_unit_test(got_names_a_message_and_its_parts),
        cmocka_unit_test(bad_messages_are_refused),
        cmocka_unit_test(json_strings_are_escaped),
        cmocka_unit_test(listen_spec),
        cmocka_unit_test(upload_names),
        cmocka_unit_test(program_folder_paths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
