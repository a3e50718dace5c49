/* src/msg: LCM datagrams, command validation, the generated types' round
 * trips, URLs, the status JSON; and a loopback trip through the transport
 * where this machine can join a multicast group (skipped elsewhere). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "ncp_ax_status_t.h"
#include "ncpar/auth.h"
#include "ncpar/msg.h"

/* A key file of the tests' own (the transport refuses to open without one). */
static char path[64];
static void remove_key_file(void)
{
    unlink(path);
}

static const char *test_key_file(void)
{
    if (path[0])
        return path;
    snprintf(path, sizeof path, "/tmp/test_msg-%d.key", (int)getpid());
    atexit(remove_key_file);
    struct ncp_diag d;
    uint8_t key[NCP_AUTH_KEY_BYTES];
    unlink(path);
    assert_int_equal(ncp_auth_load_key(path, 1, key, &d), 0);
    return path;
}

static struct ncp_auth *test_auth(void)
{
    uint8_t key[NCP_AUTH_KEY_BYTES];
    struct ncp_diag d;
    assert_int_equal(ncp_auth_load_key(test_key_file(), 0, key, &d), 0);
    return ncp_auth_new(key);
}

static int open_msg(struct ncp_msg **m, const char *url, const char *prefix, struct ncp_diag *d)
{
    const struct ncp_msg_opts o = { .url = url, .prefix = prefix, .key_file = test_key_file() };
    return ncp_msg_open(m, &o, d);
}

static const uint8_t lc02[4] = {0x4c, 0x43, 0x30, 0x32};

static ncp_command_t good_command(void)
{
    ncp_command_t c;
    memset(&c, 0, sizeof c);
    c.utime = 1700000000000000;
    c.client_id = 12345;
    c.seq = 7;
    c.kind = NCP_COMMAND_T_JOG;
    memcpy(c.text, "X", 2);
    c.value[0] = 300.0;
    c.ivalue[0] = -1;
    return c;
}

static int encode_command(const ncp_command_t *c, uint8_t *buf, size_t size)
{
    int n = ncp_command_t_encode(buf, 0, (int)size, c);
    assert_true(n > 0);
    return n;
}

/* ---- datagrams ----------------------------------------------------------- */

static void test_datagram_good(void **state)
{
    (void)state;
    uint8_t buf[64];
    int h = ncp_msg_frame_header(buf, sizeof buf, 0x01020304, "NCP_CMD");
    assert_int_equal(h, 8 + 8);
    assert_memory_equal(buf, lc02, 4);
    assert_int_equal(buf[4], 1);
    assert_int_equal(buf[7], 4);
    memcpy(buf + h, "abc", 3);
    const char *ch;
    const uint8_t *p;
    size_t plen;
    assert_int_equal(ncp_msg_parse_datagram(buf, (size_t)h + 3, &ch, &p, &plen), 0);
    assert_string_equal(ch, "NCP_CMD");
    assert_int_equal(plen, 3);
    assert_memory_equal(p, "abc", 3);
    /* an empty payload is still a datagram (not a command) */
    assert_int_equal(ncp_msg_parse_datagram(buf, (size_t)h, &ch, &p, &plen), 0);
    assert_int_equal(plen, 0);
}

static void test_datagram_bad(void **state)
{
    (void)state;
    uint8_t buf[128];
    const char *ch;
    const uint8_t *p;
    size_t plen;
    int h = ncp_msg_frame_header(buf, sizeof buf, 1, "NCP_CMD");
    buf[3] = 0x31; /* "LC01" */
    assert_int_equal(ncp_msg_parse_datagram(buf, (size_t)h, &ch, &p, &plen), -1);
    /* no NUL after the channel */
    h = ncp_msg_frame_header(buf, sizeof buf, 1, "NCP_CMD");
    assert_int_equal(ncp_msg_parse_datagram(buf, (size_t)h - 1, &ch, &p, &plen), -1);
    /* empty channel */
    memcpy(buf, lc02, 4);
    buf[8] = 0;
    buf[9] = 'x';
    assert_int_equal(ncp_msg_parse_datagram(buf, 10, &ch, &p, &plen), -1);
    /* a channel longer than LCM's 63 characters */
    memset(buf + 8, 'A', 80);
    buf[88] = 0;
    assert_int_equal(ncp_msg_parse_datagram(buf, 89, &ch, &p, &plen), -1);
    /* too short for a header */
    assert_int_equal(ncp_msg_parse_datagram(buf, 5, &ch, &p, &plen), -1);
    /* an LC03 fragment, even the first one with its channel */
    memset(buf, 0, sizeof buf);
    memcpy(buf, "LC03", 4);
    memcpy(buf + 20, "NCP_CMD", 8);
    assert_int_equal(ncp_msg_parse_datagram(buf, 40, &ch, &p, &plen), -1);
    /* frame_header refuses what LCM cannot carry */
    assert_int_equal(ncp_msg_frame_header(buf, sizeof buf, 1, ""), -1);
    assert_int_equal(ncp_msg_frame_header(buf, 10, 1, "NCP_STATUS"), -1);
}

/* ---- commands ------------------------------------------------------------ */

static void test_command_good(void **state)
{
    (void)state;
    ncp_command_t c = good_command(), d;
    uint8_t buf[1024];
    int n = encode_command(&c, buf, sizeof buf);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), 0);
    assert_int_equal(d.client_id, 12345);
    assert_int_equal(d.seq, 7);
    assert_int_equal(d.kind, NCP_COMMAND_T_JOG);
    assert_string_equal((const char *)d.text, "X");
    assert_true(d.value[0] == 300.0);
    assert_int_equal(d.ivalue[0], -1);
}

static void test_command_garbage(void **state)
{
    (void)state;
    ncp_command_t c = good_command(), d;
    uint8_t buf[1024];
    int n = encode_command(&c, buf, sizeof buf);

    buf[0] ^= 0x55; /* wrong fingerprint */
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);
    buf[0] ^= 0x55;
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n - 1, &d), -1); /* truncated */
    assert_int_equal(ncp_msg_decode_command(buf, 4, &d), -1);
    buf[n] = 0;
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n + 1, &d), -1); /* too long */

    c = good_command();
    memset(c.text, 'G', sizeof c.text); /* text without NUL */
    n = encode_command(&c, buf, sizeof buf);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);

    static const int16_t bad_kinds[] = {0, 21, -1, 1000};
    for (size_t i = 0; i < sizeof bad_kinds / sizeof bad_kinds[0]; i++) {
        c = good_command();
        c.kind = bad_kinds[i];
        n = encode_command(&c, buf, sizeof buf);
        assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);
    }
    for (int16_t k = NCP_COMMAND_T_LOAD; k <= NCP_COMMAND_T_FILES; k++) {
        c = good_command();
        c.kind = k;
        n = encode_command(&c, buf, sizeof buf);
        assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), 0);
    }

    c = good_command();
    c.client_id = 0;
    n = encode_command(&c, buf, sizeof buf);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);

    c = good_command();
    c.value[1] = NAN;
    n = encode_command(&c, buf, sizeof buf);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);
    c.value[1] = INFINITY;
    n = encode_command(&c, buf, sizeof buf);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);

    /* another type's encoding on CMD */
    ncp_ack_t a;
    memset(&a, 0, sizeof a);
    n = ncp_ack_t_encode(buf, 0, (int)sizeof buf, &a);
    assert_int_equal(ncp_msg_decode_command(buf, (size_t)n, &d), -1);
}

/* ---- the four types' round trips ------------------------------------------ */

static void test_round_trips(void **state)
{
    (void)state;
    ncp_command_t c = good_command(), c2;
    uint8_t buf[2048];
    int n = ncp_command_t_encode(buf, 0, (int)sizeof buf, &c);
    assert_int_equal(n, ncp_command_t_encoded_size(&c));
    assert_int_equal(ncp_command_t_decode(buf, 0, n, &c2), n);
    assert_true(c2.utime == c.utime && c2.client_id == c.client_id && c2.seq == c.seq);
    assert_true(c2.channel == c.channel && c2.kind == c.kind);
    assert_memory_equal(c2.text, c.text, sizeof c.text);
    assert_memory_equal(c2.value, c.value, sizeof c.value);
    assert_memory_equal(c2.ivalue, c.ivalue, sizeof c.ivalue);

    ncp_ack_t a, a2;
    memset(&a, 0, sizeof a);
    a.utime = 42;
    a.client_id = -5;
    a.seq = 99;
    a.channel = 1;
    a.result = NCP_ACK_T_REJECTED;
    a.state = NCP_STATUS_T_FAULT;
    snprintf((char *)a.reason, sizeof a.reason, "not homed: Z");
    n = ncp_ack_t_encode(buf, 0, (int)sizeof buf, &a);
    assert_int_equal(ncp_ack_t_decode(buf, 0, n, &a2), n);
    assert_true(a2.utime == 42 && a2.client_id == -5 && a2.seq == 99 && a2.channel == 1);
    assert_true(a2.result == NCP_ACK_T_REJECTED && a2.state == NCP_STATUS_T_FAULT);
    assert_memory_equal(a2.reason, a.reason, sizeof a.reason);

    ncp_status_t s, s2;
    memset(&s, 0, sizeof s);
    s.utime = 1;
    s.seq = 1234567890123;
    s.state = NCP_STATUS_T_RUNNING;
    snprintf((char *)s.program, sizeof s.program, "/tmp/a.ngc");
    s.line = 17;
    s.n_axes = 3;
    memcpy(s.axes, "XYZ", 3);
    s.homed[2] = 1;
    for (int i = 0; i < 9; i++) {
        s.pos_cmd[i] = i * 1.25;
        s.pos_act[i] = -i * 0.5;
        s.g5x_offset[i] = i;
    }
    s.vel = 1500.5;
    s.feed_override = 80;
    s.spindle_dir = -1;
    s.flood = 1;
    s.tool = 4;
    s.g5x_index = 7;
    s.garbage = 3;
    s.latency_max_us = 12.5;
    n = ncp_status_t_encode(buf, 0, (int)sizeof buf, &s);
    assert_int_equal(ncp_status_t_decode(buf, 0, n, &s2), n);
    assert_true(s2.seq == s.seq && s2.state == s.state && s2.line == 17 && s2.n_axes == 3);
    assert_memory_equal(s2.program, s.program, sizeof s.program);
    assert_memory_equal(s2.axes, s.axes, sizeof s.axes);
    assert_memory_equal(s2.homed, s.homed, sizeof s.homed);
    assert_memory_equal(s2.pos_cmd, s.pos_cmd, sizeof s.pos_cmd);
    assert_memory_equal(s2.pos_act, s.pos_act, sizeof s.pos_act);
    assert_memory_equal(s2.g5x_offset, s.g5x_offset, sizeof s.g5x_offset);
    assert_true(s2.vel == s.vel && s2.feed_override == 80 && s2.spindle_dir == -1);
    assert_true(s2.flood == 1 && s2.tool == 4 && s2.g5x_index == 7 && s2.garbage == 3);
    assert_true(s2.latency_max_us == 12.5);
    /* fits the transport's send buffer, and a short message */
    assert_true(n < 1400);

    ncp_event_t e, e2;
    memset(&e, 0, sizeof e);
    e.seq = 8;
    e.kind = NCP_EVENT_T_ERROR;
    snprintf((char *)e.file, sizeof e.file, "part.ngc");
    e.line = 12;
    e.col = 3;
    snprintf((char *)e.text, sizeof e.text, "unknown G code used");
    n = ncp_event_t_encode(buf, 0, (int)sizeof buf, &e);
    assert_int_equal(ncp_event_t_decode(buf, 0, n, &e2), n);
    assert_true(e2.seq == 8 && e2.kind == NCP_EVENT_T_ERROR && e2.line == 12 && e2.col == 3);
    assert_memory_equal(e2.file, e.file, sizeof e.file);
    assert_memory_equal(e2.text, e.text, sizeof e.text);
}

/* ---- URLs, names, JSON ---------------------------------------------------- */

static void test_url(void **state)
{
    (void)state;
    struct ncp_msg_url u;
    struct ncp_diag d;
    assert_int_equal(ncp_msg_parse_url(NCP_MSG_DEFAULT_URL, &u, &d), 0);
    assert_string_equal(u.group, "239.255.76.67");
    assert_int_equal(u.port, 7667);
    assert_int_equal(u.ttl, 0);
    assert_int_equal(u.recv_buf_size, 0);
    assert_int_equal(ncp_msg_parse_url("udpm://", &u, &d), 0);
    assert_string_equal(u.group, "239.255.76.67");
    assert_int_equal(u.port, 7667);
    assert_int_equal(ncp_msg_parse_url("udpm://224.1.2.3:9000?ttl=1&recv_buf_size=2097152",
                                       &u, &d), 0);
    assert_string_equal(u.group, "224.1.2.3");
    assert_int_equal(u.port, 9000);
    assert_int_equal(u.ttl, 1);
    assert_int_equal(u.recv_buf_size, 2097152);
    assert_int_equal(ncp_msg_parse_url("udpm://239.0.0.1", &u, &d), 0);
    assert_int_equal(u.port, 7667);

    assert_int_not_equal(ncp_msg_parse_url("tcpq://localhost:7700", &u, &d), 0);
    assert_non_null(strstr(d.msg, "only udpm://"));
    assert_int_not_equal(ncp_msg_parse_url("udpm://192.168.1.1:7667", &u, &d), 0);
    assert_non_null(strstr(d.msg, "not a multicast group"));
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:0", &u, &d), 0);
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:70000", &u, &d), 0);
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:x", &u, &d), 0);
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:7667?ttl=256", &u, &d), 0);
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:7667?ttl", &u, &d), 0);
    assert_int_not_equal(ncp_msg_parse_url("udpm://239.255.76.67:7667?foo=1", &u, &d), 0);
    assert_non_null(strstr(d.msg, "unknown option 'foo'"));
}

static void test_state_names(void **state)
{
    (void)state;
    assert_string_equal(ncp_msg_state_name(NCP_STATUS_T_IDLE), "idle");
    assert_string_equal(ncp_msg_state_name(NCP_STATUS_T_FAULT), "fault");
    assert_null(ncp_msg_state_name(10));
    assert_null(ncp_msg_state_name(-1));
    for (int i = NCP_STATUS_T_IDLE; i <= NCP_STATUS_T_FAULT; i++)
        assert_int_equal(ncp_msg_state_parse(ncp_msg_state_name(i)), i);
    assert_int_equal(ncp_msg_state_parse("Idle"), -1);
    assert_int_equal(ncp_msg_state_parse(""), -1);
    assert_string_equal(ncp_msg_estimate_name(NCP_STATUS_T_EST_RUNNING), "running");
    assert_string_equal(ncp_msg_estimate_name(NCP_STATUS_T_EST_CANCELLED), "cancelled");
    assert_null(ncp_msg_estimate_name(5));
    assert_null(ncp_msg_estimate_name(-1));
}

static void test_status_json(void **state)
{
    (void)state;
    ncp_status_t s;
    memset(&s, 0, sizeof s);
    s.state = NCP_STATUS_T_PAUSED;
    snprintf((char *)s.program, sizeof s.program, "/parts/a \"b\"\\c.ngc");
    s.line = 5;
    s.n_axes = 2;
    memcpy(s.axes, "XA", 2);
    s.homed[1] = 1;
    s.pos_cmd[0] = 1.0 / 3.0;
    s.pos_act[1] = NAN;
    s.g5x_index = 8;
    s.seq = 99;
    s.estimate_state = NCP_STATUS_T_EST_DONE;
    s.estimate_s = 101.557;
    s.estimate_path_mm = 1444.142;
    s.program_time_s = 4.5;
    s.estimate_pauses = 2;
    for (int j = 0; j < 9; j++) {
        s.estimate_min[j] = (float)-j;
        s.estimate_max[j] = (float)j + 0.5f;
    }
    s.remaining_s = -1;
    snprintf((char *)s.error, sizeof s.error, "line\nbreak");
    char buf[4096];
    int n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0 && (size_t)n == strlen(buf));
    assert_non_null(strstr(buf, "{\"state\": \"paused\", "));
    assert_non_null(strstr(buf, "\"program\": \"/parts/a \\\"b\\\"\\\\c.ngc\""));
    assert_non_null(strstr(buf, "\"homed\": {\"x\": false, \"a\": true}"));
    assert_non_null(strstr(buf, "\"pos_cmd\": {\"x\": 0.333333, \"a\": 0.000000}"));
    assert_non_null(strstr(buf, "\"pos_act\": {\"x\": 0.000000, \"a\": null}"));
    assert_non_null(strstr(buf, "\"name\": \"G59.2\""));
    assert_non_null(strstr(buf, "\"error\": \"line\\u000abreak\""));
    assert_non_null(strstr(buf, "\"seq\": 99"));
    assert_non_null(strstr(buf, "\"latency_max_us\": 0.000, "));
    /* the load's estimate and the last run's time */
    assert_non_null(strstr(buf, "\"estimate\": {\"state\": \"done\", \"program_time_s\": "
                                "101.557000, \"path_length_mm\": 1444.142000"));
    assert_non_null(strstr(buf, "\"pauses\": 2, \"extents\": {\"min\": [0.0000, -1.0000, "
                                "-2.0000, -3.0000, -4.0000, -5.0000, -6.0000, -7.0000, "
                                "-8.0000], \"max\": [0.5000, 1.5000, "));
    assert_non_null(strstr(buf, "}, \"program_time_s\": 4.500000, \"remaining_s\": null, "
                                "\"drives\": [], \"llc_dp\": 0, \"llcs\": []}"));
    /* while a run goes on: what is left; no extents found: null */
    s.remaining_s = 12.25;
    s.estimate_min[0] = 1;
    s.estimate_max[0] = 0;
    n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "\"remaining_s\": 12.250, "));
    assert_non_null(strstr(buf, "\"extents\": null}"));
    /* CiA 402 drives: state by name, statusword and last EMCY code with its meaning */
    s.n_drives = 2;
    memcpy(s.drive_axis, "XY", 2);
    s.drive_node[0] = 1;
    s.drive_node[1] = 2;
    s.drive_statusword[0] = 0x0237;
    s.drive_statusword[1] = 0x0218;
    s.drive_error[1] = (int16_t)0x8611;
    n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "\"drives\": [{\"axis\": \"X\", \"node\": 1, \"state\": "
                                "\"Operation enabled\", \"statusword\": \"0x0237\", \"error\": "
                                "\"0x0000\", \"error_text\": \"\"}, {\"axis\": \"Y\", \"node\": 2, "
                                "\"state\": \"Fault\", \"statusword\": \"0x0218\", \"error\": "
                                "\"0x8611\", \"error_text\": \"following error\"}], "));
    /* distributed axes: each LLC's state by name, its clock offset and following error */
    s.n_llcs = 2;
    s.llc_dp = 4;
    memcpy(s.llc_axis, "XZ", 2);
    s.llc_state[0] = NCP_AX_STATUS_T_RUNNING;
    s.llc_state[1] = -1;
    s.llc_clock_offset_us[0] = -12;
    s.llc_ferr_nm[0] = 3071;
    /* and each one's last error in a few words ("" none) */
    s.llc_error[1] = NCP_STATUS_T_LLC_ERR_UNHEARD;
    n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "\"llc_dp\": 4, \"llcs\": [{\"axis\": \"X\", \"state\": "
                                "\"running\", \"clock_offset_us\": -12, \"ferr_nm\": 3071, "
                                "\"error\": \"\"}, "
                                "{\"axis\": \"Z\", \"state\": \"unheard\", \"clock_offset_us\": 0, "
                                "\"ferr_nm\": 0, \"error\": \"unheard (killed or cut off)\"}]}"));
    s.llc_error[0] = NCP_STATUS_T_LLC_ERR_LOST;
    s.llc_error[1] = 99;   /* a newer NCK's: its number */
    n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "\"ferr_nm\": 3071, \"error\": \"setpoints lost\"}"));
    assert_non_null(strstr(buf, "\"ferr_nm\": 0, \"error\": \"error 99\"}]}"));
    assert_string_equal(ncp_msg_llc_state_name(NCP_AX_STATUS_T_DONE), "done");
    assert_null(ncp_msg_llc_state_name(6));
    assert_string_equal(ncp_msg_llc_error_name(NCP_STATUS_T_LLC_ERR_NONE), "");
    assert_string_equal(ncp_msg_llc_error_name(NCP_STATUS_T_LLC_ERR_FERROR), "following error");
    for (int e = NCP_STATUS_T_LLC_ERR_HLC_STOP; e <= NCP_STATUS_T_LLC_ERR_OTHER; e++)
        assert_true(ncp_msg_llc_error_name(e) && ncp_msg_llc_error_name(e)[0]);
    assert_null(ncp_msg_llc_error_name(1));   /* the program's end is no error */
    assert_null(ncp_msg_llc_error_name(-1));
    /* nothing and no state: nulls */
    memset(&s, 0, sizeof s);
    s.state = 42;
    n = ncp_msg_status_json(&s, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "\"state\": null, \"program\": null"));
    assert_non_null(strstr(buf, "\"g5x\": {\"index\": 0, \"name\": null"));
    assert_non_null(strstr(buf, "\"estimate\": {\"state\": \"none\""));
    s.estimate_state = 9;
    assert_true(ncp_msg_status_json(&s, buf, sizeof buf) > 0);
    assert_non_null(strstr(buf, "\"estimate\": {\"state\": null"));
    assert_int_equal(ncp_msg_status_json(&s, buf, 40), -1);
}

/* An event as `cnc-ctl events --json` prints it: every kind by name, text
 * escaped, an empty file null, a full buffer refused. */
static void test_event_json(void **state)
{
    (void)state;
    static const char *const kinds[] = {"info", "msg", "debug", "print", "error", "fault"};
    for (int k = NCP_EVENT_T_INFO; k <= NCP_EVENT_T_FAULT; k++)
        assert_string_equal(ncp_msg_event_kind_name(k), kinds[k]);
    assert_null(ncp_msg_event_kind_name(6));
    assert_null(ncp_msg_event_kind_name(-1));
    ncp_event_t e;
    memset(&e, 0, sizeof e);
    e.kind = NCP_EVENT_T_ERROR;
    e.channel = 3;
    e.seq = 12;
    e.utime = 1700000000000001;
    snprintf((char *)e.file, sizeof e.file, "/parts/a.ngc");
    e.line = 7;
    e.col = 4;
    snprintf((char *)e.text, sizeof e.text, "\"R\" word\tmissing");
    char buf[2048];
    int n = ncp_msg_event_json(&e, buf, sizeof buf);
    assert_true(n > 0 && (size_t)n == strlen(buf));
    assert_string_equal(buf, "{\"kind\": \"error\", \"channel\": 3, \"seq\": 12, "
                             "\"utime\": 1700000000000001, \"file\": \"/parts/a.ngc\", "
                             "\"line\": 7, \"col\": 4, \"text\": \"\\\"R\\\" word\\u0009missing\"}");
    memset(&e, 0, sizeof e);
    e.kind = 99;
    n = ncp_msg_event_json(&e, buf, sizeof buf);
    assert_true(n > 0);
    assert_non_null(strstr(buf, "{\"kind\": null, "));
    assert_non_null(strstr(buf, "\"file\": null, "));
    assert_int_equal(ncp_msg_event_json(&e, buf, 30), -1);
}

/* The modal codes in force, spelt as written: code*10 with a decimal, G64's
 * P and Q in the text only when set, -1 slots left out. */
static void test_active_codes(void **state)
{
    (void)state;
    ncp_status_t s;
    memset(&s, 0, sizeof s);
    static const int16_t g[13] = { 10, 170, 910, 901, 940, 200, 400, 490, 980, 590, 640, 970, 80 };
    static const int16_t m[4] = { 3, -1, 8, 48 };
    memcpy(s.gcodes, g, sizeof g);
    memcpy(s.mcodes, m, sizeof m);
    s.g64_p = 0.05;
    char buf[256];
    int n = ncp_msg_active_codes_text(&s, buf, sizeof buf);
    assert_true(n > 0 && (size_t)n == strlen(buf));
    assert_string_equal(buf, "G1 G17 G91 G90.1 G94 G20 G40 G49 G98 G59 G64 P0.05 Q0 G97 G8 "
                             "M3 M8 M48");
    assert_int_equal(ncp_msg_active_codes_text(&s, buf, 20), -1);
    s.g64_p = 0;
    s.gcodes[9] = 592;   /* G59.2 */
    s.gcodes[0] = 0;     /* G0 */
    assert_true(ncp_msg_active_codes_text(&s, buf, sizeof buf) > 0);
    assert_non_null(strstr(buf, "G0 G17"));
    assert_non_null(strstr(buf, "G59.2 G64 G97"));
    char js[8192];
    assert_true(ncp_msg_status_json(&s, js, sizeof js) > 0);
    assert_non_null(strstr(js, "\"gcodes\": [\"G0\", \"G17\", \"G91\", \"G90.1\""));
    assert_non_null(strstr(js, "\"mcodes\": [\"M3\", \"M8\", \"M48\"], \"g64\": {\"p\": 0, \"q\": 0}"));
    char one[8];
    assert_int_equal(ncp_msg_code_name('G', -1, one, sizeof one), -1);
    assert_int_equal(ncp_msg_code_name('G', 611, one, sizeof one), 5);
    assert_string_equal(one, "G61.1");
}

/* ---- loopback through the transport ---------------------------------------- */

struct got {
    int n;
    ncp_command_t last;
};

static void on_cmd(void *ctx, const ncp_command_t *cmd)
{
    struct got *g = ctx;
    g->n++;
    g->last = *cmd;
}

static void send_raw(int fd, const struct sockaddr_in *to, const uint8_t *buf, size_t len)
{
    assert_int_equal(sendto(fd, buf, len, 0, (const struct sockaddr *)to, sizeof *to),
                     (ssize_t)len);
}

static void test_loopback(void **state)
{
    (void)state;
    char prefix[32];
    snprintf(prefix, sizeof prefix, "T%d_", (int)getpid());
    static const char url[] = "udpm://239.255.76.68:7769?ttl=0";
    struct ncp_msg *m;
    struct ncp_diag d;
    if (open_msg(&m, url, prefix, &d) != 0) {
        printf("no multicast here (%s)\n", d.msg);
        skip();
    }
    /* a second process's socket on the same group and port, as liblcm's */
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    assert_true(fd >= 0);
    int one = 1;
    unsigned char ttl = 0;
    assert_int_equal(setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one), 0);
    assert_int_equal(setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl), 0);
    struct sockaddr_in to;
    memset(&to, 0, sizeof to);
    to.sin_family = AF_INET;
    to.sin_port = htons(7769);
    inet_pton(AF_INET, "239.255.76.68", &to.sin_addr);
    struct sockaddr_in any = to;
    any.sin_addr.s_addr = htonl(INADDR_ANY);
    assert_int_equal(bind(fd, (struct sockaddr *)&any, sizeof any), 0);
    struct ip_mreq mreq = {.imr_multiaddr = to.sin_addr};
    assert_int_equal(setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq), 0);

    char ch_cmd[64], ch_other[64];
    snprintf(ch_cmd, sizeof ch_cmd, "%sCMD", prefix);
    snprintf(ch_other, sizeof ch_other, "%sSTATUSX", prefix);
    uint8_t buf[2048];
    struct ncp_auth *a = test_auth();
    ncp_command_t c = good_command();
    int h = ncp_msg_frame_header(buf, sizeof buf, 1, ch_cmd);
    int n = ncp_command_t_encode(buf, h, (int)sizeof buf - h, &c);
    send_raw(fd, &to, buf, (size_t)(h + n));        /* no seal: auth_failed */
    size_t sealed = ncp_auth_seal(a, ch_cmd, buf + h, (size_t)n, 0, ncp_auth_now_ns());
    send_raw(fd, &to, buf, (size_t)h + sealed);     /* the one handed on */
    send_raw(fd, &to, buf, (size_t)h + sealed - 3); /* truncated: auth_failed */
    buf[h + 20] ^= 1;
    send_raw(fd, &to, buf, (size_t)h + sealed);     /* one bit changed: auth_failed */
    buf[h + 20] ^= 1;
    send_raw(fd, &to, (const uint8_t *)"hello", 5); /* not LCM: garbage */
    h = ncp_msg_frame_header(buf, sizeof buf, 2, ch_other);
    n = ncp_command_t_encode(buf, h, (int)sizeof buf - h, &c);
    send_raw(fd, &to, buf, (size_t)(h + n)); /* another channel: skipped */
    /* a valid command sealed for another channel, sent on CMD: refused */
    h = ncp_msg_frame_header(buf, sizeof buf, 3, ch_cmd);
    n = ncp_command_t_encode(buf, h, (int)sizeof buf - h, &c);
    sealed = ncp_auth_seal(a, ch_other, buf + h, (size_t)n, 0, ncp_auth_now_ns());
    send_raw(fd, &to, buf, (size_t)h + sealed);

    ncp_status_t s;
    memset(&s, 0, sizeof s);
    s.seq = 5;
    assert_int_equal(ncp_msg_send_status(m, &s), 0);

    struct got g = {0};
    struct ncp_msg_stats st;
    for (int i = 0; i < 50; i++) {
        assert_true(ncp_msg_poll(m, 20, on_cmd, &g) >= 0);
        ncp_msg_get_stats(m, &st);
        if (st.received >= 8)
            break;
    }
    assert_int_equal(g.n, 1);
    assert_int_equal(g.last.client_id, 12345);
    assert_int_equal(g.last.kind, NCP_COMMAND_T_JOG);
    assert_int_equal(st.received, 8); /* seven sent here, and our own status */
    assert_int_equal(st.commands, 1);
    assert_int_equal(st.auth_failed, 4);
    assert_int_equal(st.garbage, 1);
    assert_int_equal(st.sent, 1);

    /* the other socket reads our status as an LCM client would */
    ssize_t r;
    const char *ch = NULL;
    const uint8_t *p;
    size_t plen = 0;
    do {
        r = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    } while (r > 0 && (ncp_msg_parse_datagram(buf, (size_t)r, &ch, &p, &plen) != 0 ||
                       strstr(ch, "STATUS") == NULL || strstr(ch, "STATUSX") != NULL));
    assert_true(r > 0);
    ncp_status_t s2;
    size_t body;
    int64_t sent_ns;
    assert_int_equal(ncp_auth_check(a, ch, (uint8_t *)p, plen, &body, &sent_ns), NCP_AUTH_OK);
    assert_int_equal(ncp_status_t_decode(p, 0, (int)body, &s2), (int)body);
    assert_int_equal(s2.seq, 5);
    ncp_auth_free(a);
    close(fd);
    ncp_msg_close(m);
}

/* Which of 40 messages on channel A come through INJECT_LOSS 0.5 (a bit
 * each), with i % 3 messages on channel B before the i-th where mixed; -1
 * where this machine has no multicast. *lost: all the messages lost. */
static int64_t arrivals_on_a(int mixed, int *lost)
{
    char prefix[32], ch_a[64], ch_b[64];
    snprintf(prefix, sizeof prefix, "D%d_", (int)getpid());
    snprintf(ch_a, sizeof ch_a, "%sA", prefix);
    snprintf(ch_b, sizeof ch_b, "%sB", prefix);
    static const char url[] = "udpm://239.255.76.68:7771?ttl=0";
    struct ncp_msg *rx, *tx;
    struct ncp_diag d;
    if (open_msg(&rx, url, prefix, &d) != 0)
        return -1;
    assert_int_equal(open_msg(&tx, url, prefix, &d), 0);
    assert_int_equal(ncp_msg_subscribe(rx, ch_b), 0);
    assert_int_equal(ncp_msg_subscribe(rx, ch_a), 1);
    const struct ncp_msg_inject in = { 0.5, 0, 9 };
    assert_int_equal(ncp_msg_set_inject(rx, &in), 0);
    uint64_t sent = 0;
    for (int i = 0; i < 40; i++) {
        uint8_t k = (uint8_t)i;
        for (int j = 0; j < (mixed ? i % 3 : 0); j++, sent++)
            assert_int_equal(ncp_msg_publish(tx, ch_b, &k, 1), 0);
        assert_int_equal(ncp_msg_publish(tx, ch_a, &k, 1), 0);
        sent++;
    }
    int64_t got = 0;
    struct ncp_msg_stats st;
    for (int tries = 0; tries < 500; tries++) {
        int sub;
        const uint8_t *p;
        size_t len;
        int r = ncp_msg_take(rx, 0, &sub, &p, &len);
        assert_true(r >= 0);
        if (r == 1 && sub == 1 && len == 1 && p[0] < 40)
            got |= (int64_t)1 << p[0];
        ncp_msg_get_stats(rx, &st);
        if (st.taken >= sent && r == 0)
            break;
        if (r == 0)
            usleep(1000);
    }
    assert_int_equal(st.taken, sent);
    *lost = (int)st.inject_lost;
    ncp_msg_close(tx);
    ncp_msg_close(rx);
    return got;
}

static void test_loss_per_channel(void **state)
{
    (void)state;
    int lost_alone, lost_mixed;
    int64_t alone = arrivals_on_a(0, &lost_alone);
    if (alone < 0) {
        printf("no multicast here\n");
        skip();
    }
    int64_t mixed = arrivals_on_a(1, &lost_mixed);
    /* about half of A's came through, the same ones with and without B's
     * traffic between them (B's own messages are diced apart) */
    int n = __builtin_popcountll((unsigned long long)alone);
    assert_in_range(n, 8, 32);
    assert_true(alone == mixed);
    assert_true(lost_mixed > lost_alone);
}

static void test_open_errors(void **state)
{
    (void)state;
    struct ncp_msg *m;
    struct ncp_diag d;
    assert_int_not_equal(open_msg(&m, "udpm://10.0.0.1:7667", NULL, &d), 0);
    assert_null(m);
    assert_non_null(strstr(d.msg, "not a multicast group"));
    assert_int_not_equal(
        open_msg(&m, NULL, "A_PREFIX_LONGER_THAN_THIRTY_TWO_CHARACTERS_", &d), 0);
    assert_non_null(strstr(d.msg, "prefix"));
    const struct ncp_msg_opts nokey = { .url = NULL };
    assert_int_not_equal(ncp_msg_open(&m, &nokey, &d), 0);
    assert_null(m);
    assert_non_null(strstr(d.msg, "key"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_datagram_good), cmocka_unit_test(test_datagram_bad),
        cmocka_unit_test(test_command_good),  cmocka_unit_test(test_command_garbage),
        cmocka_unit_test(test_round_trips),   cmocka_unit_test(test_url),
        cmocka_unit_test(test_state_names),   cmocka_unit_test(test_status_json),
        cmocka_unit_test(test_active_codes),  cmocka_unit_test(test_event_json),
        cmocka_unit_test(test_open_errors),   cmocka_unit_test(test_loopback),
        cmocka_unit_test(test_loss_per_channel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
