/* The trailer's MAC and the status's encryption (see ncpar/auth.h).
 *
 * HMAC-SHA256 is built here on OpenSSL's SHA-256 with the key's inner and
 * outer pads hashed once at ncp_auth_new: each message then costs two
 * SHA-256 runs over copies of those states, with no allocation (OpenSSL 3's
 * HMAC() and EVP_MAC duplicate contexts on the heap per call, which the
 * distributed NCK's position loops must not do). The low-level SHA-256
 * calls are deprecated in OpenSSL 3 in favour of EVP, for that reason kept. */
#define OPENSSL_SUPPRESS_DEPRECATED
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/sha.h>

#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

#include "ncpar/auth.h"

#define MAGIC_PLAIN "NCA1"
#define MAGIC_SEALED_SECRET "NCE1"
#define DOMAIN "ncpar-lcm-1"
#define HMAC_BLOCK 64

struct ncp_auth {
    SHA256_CTX inner, outer;     /* after the key's ipad and opad blocks */
    uint8_t enc_key[32];         /* ChaCha20's, derived from the key */
    EVP_CIPHER_CTX *enc, *dec;
    int64_t last_sent_ns;
    uint32_t salt;
};

static void put_be64(uint8_t *p, uint64_t v)
{
    for (int i = 7; i >= 0; i--, v >>= 8)
        p[i] = (uint8_t)v;
}

static uint64_t get_be64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v = v << 8 | p[i];
    return v;
}

static void put_be32(uint8_t *p, uint32_t v)
{
    for (int i = 3; i >= 0; i--, v >>= 8)
        p[i] = (uint8_t)v;
}

static void hmac_pads(struct ncp_auth *a, const uint8_t *key, size_t n)
{
    uint8_t block[HMAC_BLOCK];
    memset(block, 0, sizeof block);
    memcpy(block, key, n);   /* n <= 64: no pre-hash of the key needed */
    uint8_t pad[HMAC_BLOCK];
    for (int i = 0; i < HMAC_BLOCK; i++)
        pad[i] = block[i] ^ 0x36;
    SHA256_Init(&a->inner);
    SHA256_Update(&a->inner, pad, sizeof pad);
    for (int i = 0; i < HMAC_BLOCK; i++)
        pad[i] = block[i] ^ 0x5c;
    SHA256_Init(&a->outer);
    SHA256_Update(&a->outer, pad, sizeof pad);
    OPENSSL_cleanse(block, sizeof block);
    OPENSSL_cleanse(pad, sizeof pad);
}

/* HMAC-SHA256(key, DOMAIN NUL channel NUL body trailer-head) into out. */
static void mac_of(const struct ncp_auth *a, const char *channel, const uint8_t *body,
                   size_t len, const uint8_t *head, uint8_t out[SHA256_DIGEST_LENGTH])
{
    SHA256_CTX c = a->inner;
    SHA256_Update(&c, DOMAIN, sizeof DOMAIN);          /* with its NUL */
    SHA256_Update(&c, channel, strlen(channel) + 1);
    SHA256_Update(&c, body, len);
    SHA256_Update(&c, head, 16);
    uint8_t inner[SHA256_DIGEST_LENGTH];
    SHA256_Final(inner, &c);
    c = a->outer;
    SHA256_Update(&c, inner, sizeof inner);
    SHA256_Final(out, &c);
}

struct ncp_auth *ncp_auth_new(const uint8_t key[NCP_AUTH_KEY_BYTES])
{
    struct ncp_auth *a = calloc(1, sizeof *a);
    if (a == NULL)
        return NULL;
    hmac_pads(a, key, NCP_AUTH_KEY_BYTES);
    /* the encryption key: the MAC of a label no message can carry (its
     * channel part is empty, which no LCM channel is) */
    static const uint8_t label[16] = "ncpar-encrypt-1";
    uint8_t digest[SHA256_DIGEST_LENGTH];
    mac_of(a, "", label, 0, label, digest);
    memcpy(a->enc_key, digest, sizeof a->enc_key);
    OPENSSL_cleanse(digest, sizeof digest);
    a->enc = EVP_CIPHER_CTX_new();
    a->dec = EVP_CIPHER_CTX_new();
    if (a->enc == NULL || a->dec == NULL ||
        EVP_EncryptInit_ex(a->enc, EVP_chacha20(), NULL, a->enc_key, NULL) != 1 ||
        EVP_DecryptInit_ex(a->dec, EVP_chacha20(), NULL, a->enc_key, NULL) != 1) {
        ncp_auth_free(a);
        return NULL;
    }
    if (getrandom(&a->salt, sizeof a->salt, 0) != (ssize_t)sizeof a->salt)
        a->salt = (uint32_t)ncp_auth_now_ns() ^ 0x9e3779b9u;
    return a;
}

void ncp_auth_free(struct ncp_auth *a)
{
    if (a == NULL)
        return;
    EVP_CIPHER_CTX_free(a->enc);
    EVP_CIPHER_CTX_free(a->dec);
    OPENSSL_cleanse(a, sizeof *a);
    free(a);
}

int64_t ncp_auth_now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* ChaCha20 over msg in place; its 16-byte IV is a block counter of 0 and
 * the trailer's sent_ns and salt, unique per message of a key. */
static int crypt_body(EVP_CIPHER_CTX *ctx, int encrypt, const uint8_t *head, uint8_t *msg,
                      size_t len)
{
    uint8_t iv[16] = { 0 };
    memcpy(iv + 4, head + 4, 12);
    int out = 0;
    if (EVP_CipherInit_ex(ctx, NULL, NULL, NULL, iv, encrypt) != 1)
        return -1;
    if (len > 0 && EVP_CipherUpdate(ctx, msg, &out, msg, (int)len) != 1)
        return -1;
    return 0;
}

size_t ncp_auth_seal(struct ncp_auth *a, const char *channel, uint8_t *msg, size_t len,
                     int encrypt, int64_t now_ns)
{
    if (now_ns <= a->last_sent_ns)
        now_ns = a->last_sent_ns + 1;
    a->last_sent_ns = now_ns;
    uint8_t *t = msg + len;
    memcpy(t, encrypt ? MAGIC_SEALED_SECRET : MAGIC_PLAIN, 4);
    put_be64(t + 4, (uint64_t)now_ns);
    put_be32(t + 12, a->salt);
    if (encrypt && crypt_body(a->enc, 1, t, msg, len) != 0)
        memset(msg, 0, len);   /* never send the plain text marked secret */
    uint8_t mac[SHA256_DIGEST_LENGTH];
    mac_of(a, channel, msg, len, t, mac);
    memcpy(t + 16, mac, NCP_AUTH_MAC_BYTES);
    return len + NCP_AUTH_TRAILER_BYTES;
}

enum ncp_auth_verdict ncp_auth_check(const struct ncp_auth *a, const char *channel, uint8_t *msg,
                                     size_t len, size_t *body_len, int64_t *sent_ns)
{
    if (len < NCP_AUTH_TRAILER_BYTES)
        return NCP_AUTH_NO_TRAILER;
    size_t n = len - NCP_AUTH_TRAILER_BYTES;
    const uint8_t *t = msg + n;
    int secret = memcmp(t, MAGIC_SEALED_SECRET, 4) == 0;
    if (!secret && memcmp(t, MAGIC_PLAIN, 4) != 0)
        return NCP_AUTH_NO_TRAILER;
    uint8_t mac[SHA256_DIGEST_LENGTH];
    mac_of(a, channel, msg, n, t, mac);
    if (CRYPTO_memcmp(mac, t + 16, NCP_AUTH_MAC_BYTES) != 0)
        return NCP_AUTH_BAD_MAC;
    if (secret && crypt_body(a->dec, 0, t, msg, n) != 0)
        return NCP_AUTH_BAD_MAC;
    *body_len = n;
    *sent_ns = (int64_t)get_be64(t + 4);
    return NCP_AUTH_OK;
}
