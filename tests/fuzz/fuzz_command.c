/* libFuzzer target for what the NCK does with a datagram from the network
 * before anything acts on it: LC02 framing, the seal (ncpar/auth.h) and the
 * command decoder. The first byte chooses the path:
 *   even: the rest is a datagram as it comes off the socket (forged: the
 *         seal must refuse it, or it is a frame this target sealed before);
 *   odd:  the rest is a command's encoding, sealed here with the key, so the
 *         decoder behind the seal is fuzzed too.
 * Checked beyond "no crash": a message accepted by the seal round-trips (a
 * sealed copy checks, one flipped byte of it does not), and a decoded command
 * is what the decoder promises (known kind, client id, NUL in its text,
 * finite numbers). */
#include "ncpar/auth.h"
#include "ncpar/msg.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CHANNEL "NCP_CMD"

static struct ncp_auth *the_auth(void)
{
    static struct ncp_auth *a;
    if (a == NULL) {
        static const uint8_t key[NCP_AUTH_KEY_BYTES] = "fuzz-key-fuzz-key-fuzz-key-fuzz";
        a = ncp_auth_new(key);
        if (a == NULL)
            abort();
    }
    return a;
}

static void check_command(const ncp_command_t *c)
{
    if (c->kind < NCP_COMMAND_T_LOAD || c->kind > NCP_COMMAND_T_SET_INPUT || c->client_id == 0 ||
        memchr(c->text, 0, sizeof c->text) == NULL)
        abort();
    for (int i = 0; i < 4; i++)
        if (!isfinite(c->value[i]))
            abort();
}

static void decode(uint8_t *body, size_t len)
{
    ncp_command_t c;
    if (ncp_msg_decode_command(body, len, &c) == 0)
        check_command(&c);
}

/* A datagram off the socket: frame, seal, decoder, as the transport takes it. */
static void from_socket(const uint8_t *data, size_t size)
{
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return;
    memcpy(copy, data, size);
    const char *channel;
    const uint8_t *payload;
    size_t plen, body;
    int64_t sent;
    if (ncp_msg_parse_datagram(copy, size, &channel, &payload, &plen) == 0 &&
        strcmp(channel, CHANNEL) == 0 &&
        ncp_auth_check(the_auth(), channel, (uint8_t *)payload, plen, &body, &sent) ==
            NCP_AUTH_OK)
        decode((uint8_t *)payload, body);
    free(copy);
}

/* A command's encoding sealed here: it must check, decode as the decoder
 * says, and refuse any one byte changed. */
static void sealed_here(const uint8_t *data, size_t size)
{
    if (size > 4096)
        return;
    uint8_t buf[4096 + NCP_AUTH_TRAILER_BYTES];
    memcpy(buf, data, size);
    size_t n = ncp_auth_seal(the_auth(), CHANNEL, buf, size, 0, 1);
    size_t body;
    int64_t sent;
    if (ncp_auth_check(the_auth(), CHANNEL, buf, n, &body, &sent) != NCP_AUTH_OK || body != size)
        abort();
    size_t at = size ? data[0] % n : 0;
    buf[at] ^= 0x01;
    if (ncp_auth_check(the_auth(), CHANNEL, buf, n, &body, &sent) == NCP_AUTH_OK)
        abort();
    buf[at] ^= 0x01;
    decode(buf, size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0)
        return 0;
    if (data[0] & 1)
        sealed_here(data + 1, size - 1);
    else
        from_socket(data + 1, size - 1);
    return 0;
}
