/* LCM's datagrams as liblcm's udpm transport writes them, and the one message
 * the NCK reads from them (command_t), checked before anyone acts on it.
 *
 * An LC02 datagram ("short message", anything up to a UDP datagram):
 *   uint32 magic 0x4c433032 ("LC02"), uint32 sequence number, both big-endian,
 *   the channel name and its NUL, the payload (an lcm-gen encoding: 8-byte
 *   fingerprint, then the fields big-endian).
 * LC03 ("LC03", fragments of larger messages) is never a command here. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "msg_int.h"
#include "ncpar/msg.h"

static uint32_t get_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

int ncp_msg_parse_datagram(const uint8_t *buf, size_t len, const char **channel,
                           const uint8_t **payload, size_t *payload_len)
{
    if (len < NCP_LC_SHORT_HEADER + 2 || get_be32(buf) != NCP_LC02_MAGIC)
        return -1;
    const uint8_t *name = buf + NCP_LC_SHORT_HEADER;
    size_t room = len - NCP_LC_SHORT_HEADER;
    if (room > NCP_LC_CHANNEL_MAX + 1)
        room = NCP_LC_CHANNEL_MAX + 1;
    const uint8_t *nul = memchr(name, 0, room);
    if (nul == NULL || nul == name)
        return -1;
    *channel = (const char *)name;
    *payload = nul + 1;
    *payload_len = len - (size_t)(nul + 1 - buf);
    return 0;
}

const char *ncp_msg_fragment_channel(const uint8_t *buf, size_t len)
{
    if (len < NCP_LC_LONG_HEADER + 2 || get_be32(buf) != NCP_LC03_MAGIC)
        return NULL;
    /* fragment_no (uint16 at 16): only the first fragment names its channel */
    if (buf[16] != 0 || buf[17] != 0)
        return NULL;
    const uint8_t *name = buf + NCP_LC_LONG_HEADER;
    size_t room = len - NCP_LC_LONG_HEADER;
    if (room > NCP_LC_CHANNEL_MAX + 1)
        room = NCP_LC_CHANNEL_MAX + 1;
    const uint8_t *nul = memchr(name, 0, room);
    return nul == NULL || nul == name ? NULL : (const char *)name;
}

int ncp_msg_is_fragment(const uint8_t *buf, size_t len)
{
    return len >= 4 && get_be32(buf) == NCP_LC03_MAGIC;
}

int ncp_msg_frame_header(uint8_t *buf, size_t size, uint32_t seqno, const char *channel)
{
    size_t n = strlen(channel);
    if (n == 0 || n > NCP_LC_CHANNEL_MAX || size < NCP_LC_SHORT_HEADER + n + 1)
        return -1;
    put_be32(buf, NCP_LC02_MAGIC);
    put_be32(buf + 4, seqno);
    memcpy(buf + NCP_LC_SHORT_HEADER, channel, n + 1);
    return (int)(NCP_LC_SHORT_HEADER + n + 1);
}

int ncp_msg_decode_command(const uint8_t *payload, size_t len, ncp_command_t *cmd)
{
    /* The generated decode checks the fingerprint and every field's bounds;
     * a payload longer than the type is as wrong as a shorter one. */
    if (len > INT_MAX || ncp_command_t_decode(payload, 0, (int)len, cmd) != (int)len)
        return -1;
    if (memchr(cmd->text, 0, sizeof cmd->text) == NULL)
        return -1;
    if (cmd->kind < NCP_COMMAND_T_LOAD || cmd->kind > NCP_COMMAND_T_FILES)
        return -1;
    if (cmd->client_id == 0)
        return -1;
    /* No kind has a use for NaN or infinity (speeds, distances, percents). */
    for (size_t i = 0; i < sizeof cmd->value / sizeof cmd->value[0]; i++)
        if (!isfinite(cmd->value[i]))
            return -1;
    return 0;
}
