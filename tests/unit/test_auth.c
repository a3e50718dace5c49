/* src/auth: the key file (made, refused, read as raw or hex), where it is
 * looked for, and the seal: a round trip, every byte of a sealed message
 * flipped, another channel, another key, no trailer, encryption; the MAC
 * checked against OpenSSL's own HMAC. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ncpar/auth.h"

static char dir[64];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/test_auth-%d", (int)getpid());
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void write_file(const char *path, const void *data, size_t n, mode_t mode)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
    assert_int_equal(chmod(path, mode), 0);
}

static void test_key_made_once(void **state)
{
    (void)state;
    char path[128];
    snprintf(path, sizeof path, "%s/a/b/lcm.key", dir);
    uint8_t k1[NCP_AUTH_KEY_BYTES], k2[NCP_AUTH_KEY_BYTES];
    struct ncp_diag d;
    assert_int_not_equal(ncp_auth_load_key(path, 0, k1, &d), 0);   /* not made unasked */
    assert_non_null(strstr(d.msg, path));
    assert_int_equal(ncp_auth_load_key(path, 1, k1, &d), 0);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0600);
    assert_int_equal(st.st_size, NCP_AUTH_KEY_BYTES);
    char folder[128];
    snprintf(folder, sizeof folder, "%s/a/b", dir);
    assert_int_equal(stat(folder, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0700);
    assert_int_equal(ncp_auth_load_key(path, 1, k2, &d), 0);        /* the same, not a new one */
    assert_memory_equal(k1, k2, sizeof k1);
    /* the file's context seals as one made from its bytes checks */
    struct ncp_auth *from_file = ncp_auth_open(path, NULL, 0, &d), *from_key = ncp_auth_new(k1);
    assert_non_null(from_file);
    uint8_t msg[4 + NCP_AUTH_TRAILER_BYTES] = "abc";
    size_t n = ncp_auth_seal(from_file, "CH", msg, 4, 0, 1), body;
    int64_t sent;
    assert_int_equal(ncp_auth_check(from_key, "CH", msg, n, &body, &sent), NCP_AUTH_OK);
    ncp_auth_free(from_file);
    ncp_auth_free(from_key);
    strcat(path, ".missing");
    assert_null(ncp_auth_open(path, NULL, 0, &d));
    assert_non_null(strstr(d.msg, path));
}

static void test_key_refused(void **state)
{
    (void)state;
    mkdir(dir, 0700);
    char path[128];
    snprintf(path, sizeof path, "%s/open.key", dir);
    uint8_t raw[NCP_AUTH_KEY_BYTES] = { 1, 2, 3 }, key[NCP_AUTH_KEY_BYTES];
    struct ncp_diag d;
    write_file(path, raw, sizeof raw, 0644);
    assert_int_not_equal(ncp_auth_load_key(path, 1, key, &d), 0);
    assert_non_null(strstr(d.msg, "0644"));
    assert_non_null(strstr(d.msg, path));
    write_file(path, raw, sizeof raw, 0620);   /* writable by the group: as bad */
    assert_int_not_equal(ncp_auth_load_key(path, 0, key, &d), 0);
    write_file(path, raw, 31, 0600);           /* too short */
    assert_int_not_equal(ncp_auth_load_key(path, 0, key, &d), 0);
    assert_non_null(strstr(d.msg, "32 bytes"));
    write_file(path, raw, sizeof raw, 0600);
    assert_int_equal(ncp_auth_load_key(path, 0, key, &d), 0);
    assert_memory_equal(key, raw, sizeof raw);
    /* 64 hex digits and a newline: the same key */
    char hex[66];
    for (int i = 0; i < NCP_AUTH_KEY_BYTES; i++)
        snprintf(hex + 2 * i, 3, "%02x", raw[i]);
    hex[64] = '\n';
    write_file(path, hex, 65, 0600);
    memset(key, 0xff, sizeof key);
    assert_int_equal(ncp_auth_load_key(path, 0, key, &d), 0);
    assert_memory_equal(key, raw, sizeof raw);
    hex[3] = 'g';
    write_file(path, hex, 65, 0600);
    assert_int_not_equal(ncp_auth_load_key(path, 0, key, &d), 0);
}

static void test_key_path(void **state)
{
    (void)state;
    char buf[NCP_AUTH_PATH_MAX];
    struct ncp_diag d;
    setenv("XDG_CONFIG_HOME", "/x/cfg", 1);
    setenv("HOME", "/home/op", 1);
    assert_int_equal(ncp_auth_key_path(buf, sizeof buf, "/k/given", "/k/ini", &d), 0);
    assert_string_equal(buf, "/k/given");
    assert_int_equal(ncp_auth_key_path(buf, sizeof buf, NULL, "/k/ini", &d), 0);
    assert_string_equal(buf, "/k/ini");
    assert_int_equal(ncp_auth_key_path(buf, sizeof buf, NULL, "", &d), 0);
    assert_string_equal(buf, "/x/cfg/ncpar/lcm.key");
    setenv("XDG_CONFIG_HOME", "relative", 1);   /* ignored, as the XDG rule says */
    assert_int_equal(ncp_auth_key_path(buf, sizeof buf, NULL, NULL, &d), 0);
    assert_string_equal(buf, "/home/op/.config/ncpar/lcm.key");
    unsetenv("XDG_CONFIG_HOME");
    unsetenv("HOME");
    assert_int_not_equal(ncp_auth_key_path(buf, sizeof buf, NULL, NULL, &d), 0);
}

static const uint8_t key_a[NCP_AUTH_KEY_BYTES] = "0123456789abcdef0123456789abcdef";
static const uint8_t key_b[NCP_AUTH_KEY_BYTES] = "0123456789abcdef0123456789abcdeF";

static void test_seal_round_trip_and_every_flip(void **state)
{
    (void)state;
    struct ncp_auth *a = ncp_auth_new(key_a);
    assert_non_null(a);
    uint8_t msg[64 + NCP_AUTH_TRAILER_BYTES];
    for (int i = 0; i < 64; i++)
        msg[i] = (uint8_t)(i * 7);
    size_t n = ncp_auth_seal(a, "NCP_CMD", msg, 64, 0, 1234567890123LL);
    assert_int_equal(n, 64 + NCP_AUTH_TRAILER_BYTES);
    size_t body;
    int64_t sent;
    assert_int_equal(ncp_auth_check(a, "NCP_CMD", msg, n, &body, &sent), NCP_AUTH_OK);
    assert_int_equal(body, 64);
    assert_int_equal(sent, 1234567890123LL);
    for (size_t i = 0; i < n; i++) {
        for (int bit = 0; bit < 8; bit++) {
            msg[i] ^= (uint8_t)(1u << bit);
            enum ncp_auth_verdict v = ncp_auth_check(a, "NCP_CMD", msg, n, &body, &sent);
            /* the magic's bits make it no trailer at all; every other one a bad MAC */
            assert_true(i >= 64 && i < 68 ? v != NCP_AUTH_OK : v == NCP_AUTH_BAD_MAC);
            msg[i] ^= (uint8_t)(1u << bit);
        }
    }
    assert_int_equal(ncp_auth_check(a, "NCP_ACK", msg, n, &body, &sent), NCP_AUTH_BAD_MAC);
    assert_int_equal(ncp_auth_check(a, "NCP_CMD", msg, n - 1, &body, &sent), NCP_AUTH_NO_TRAILER);
    assert_int_equal(ncp_auth_check(a, "NCP_CMD", msg, 64, &body, &sent), NCP_AUTH_NO_TRAILER);
    struct ncp_auth *b = ncp_auth_new(key_b);
    assert_int_equal(ncp_auth_check(b, "NCP_CMD", msg, n, &body, &sent), NCP_AUTH_BAD_MAC);
    ncp_auth_free(b);
    /* the sender's time never repeats, so neither does a nonce */
    uint8_t m2[8 + NCP_AUTH_TRAILER_BYTES] = { 0 };
    ncp_auth_seal(a, "NCP_CMD", m2, 8, 0, 5);
    assert_int_equal(ncp_auth_check(a, "NCP_CMD", m2, 8 + NCP_AUTH_TRAILER_BYTES, &body, &sent),
                     NCP_AUTH_OK);
    assert_int_equal(sent, 1234567890124LL);
    ncp_auth_free(a);
}

/* The MAC is HMAC-SHA256 over what auth.h says, computed by OpenSSL's HMAC. */
static void test_mac_is_hmac_sha256(void **state)
{
    (void)state;
    struct ncp_auth *a = ncp_auth_new(key_a);
    uint8_t msg[5 + NCP_AUTH_TRAILER_BYTES] = "hello";
    size_t n = ncp_auth_seal(a, "CH", msg, 5, 0, 42);
    uint8_t input[64];
    size_t k = 0;
    memcpy(input + k, "ncpar-lcm-1", 12), k += 12;
    memcpy(input + k, "CH", 3), k += 3;
    memcpy(input + k, "hello", 5), k += 5;
    memcpy(input + k, msg + 5, 16), k += 16;
    uint8_t want[32];
    unsigned wlen = 0;
    assert_non_null(HMAC(EVP_sha256(), key_a, sizeof key_a, input, k, want, &wlen));
    assert_memory_equal(msg + 5 + 16, want, NCP_AUTH_MAC_BYTES);
    assert_int_equal(n, 5 + NCP_AUTH_TRAILER_BYTES);
    ncp_auth_free(a);
}

static void test_encrypted(void **state)
{
    (void)state;
    struct ncp_auth *a = ncp_auth_new(key_a), *b = ncp_auth_new(key_b);
    const char plain[] = "state=running program=/secret/part.ngc";
    uint8_t msg[sizeof plain + NCP_AUTH_TRAILER_BYTES];
    memcpy(msg, plain, sizeof plain);
    size_t n = ncp_auth_seal(a, "NCP_STATUS", msg, sizeof plain, 1, 7);
    assert_memory_equal(msg + sizeof plain, "NCE1", 4);
    assert_null(memmem(msg, n, "secret", 6));   /* nothing readable left */
    size_t body;
    int64_t sent;
    assert_int_equal(ncp_auth_check(b, "NCP_STATUS", msg, n, &body, &sent), NCP_AUTH_BAD_MAC);
    assert_int_equal(ncp_auth_check(a, "NCP_STATUS", msg, n, &body, &sent), NCP_AUTH_OK);
    assert_int_equal(body, sizeof plain);
    assert_memory_equal(msg, plain, sizeof plain);
    ncp_auth_free(a);
    ncp_auth_free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_key_made_once),
        cmocka_unit_test(test_key_refused),
        cmocka_unit_test(test_key_path),
        cmocka_unit_test(test_seal_round_trip_and_every_flip),
        cmocka_unit_test(test_mac_is_hmac_sha256),
        cmocka_unit_test(test_encrypted),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
