/* NMT, SYNC, heartbeat, PDO 1 and EMCY frames. */
#include <stdio.h>
#include <string.h>

#include "bytes.h"
#include "ncpar/can.h"

static void frame_init(struct ncp_can_frame *f, uint32_t id, uint8_t len)
{
    memset(f, 0, sizeof *f);
    f->id = id;
    f->len = len;
}

void ncp_nmt_frame(struct ncp_can_frame *f, enum ncp_nmt_cmd cmd, uint8_t node)
{
    frame_init(f, NCP_COB_NMT, 2);
    f->data[0] = (uint8_t)cmd;
    f->data[1] = node;
}

void ncp_sync_frame(struct ncp_can_frame *f)
{
    frame_init(f, NCP_COB_SYNC, 0);
}

void ncp_heartbeat_frame(struct ncp_can_frame *f, uint8_t node, enum ncp_nmt_state s)
{
    frame_init(f, NCP_COB_HEARTBEAT + node, 1);
    f->data[0] = (uint8_t)s;
}

const char *ncp_nmt_state_name(unsigned state)
{
    switch (state & 0x7Fu) {
    case NCP_NMT_BOOTUP: return "boot-up";
    case NCP_NMT_STOPPED: return "stopped";
    case NCP_NMT_OPERATIONAL: return "operational";
    case NCP_NMT_PREOP: return "pre-operational";
    default: return "unknown NMT state";
    }
}

void ncp_rpdo1_frame(struct ncp_can_frame *f, uint8_t node, uint16_t controlword,
                     int32_t target)
{
    frame_init(f, NCP_COB_RPDO1 + node, 6);
    ncp_put_le16(f->data, controlword);
    ncp_put_le32(f->data + 2, (uint32_t)target);
}

int ncp_rpdo1_decode(const struct ncp_can_frame *f, uint16_t *controlword,
                     int32_t *target)
{
    if (f->len < 6)
        return -1;
    *controlword = ncp_get_le16(f->data);
    *target = (int32_t)ncp_get_le32(f->data + 2);
    return 0;
}

void ncp_tpdo1_frame(struct ncp_can_frame *f, uint8_t node, uint16_t statusword,
                     int32_t actual)
{
    frame_init(f, NCP_COB_TPDO1 + node, 6);
    ncp_put_le16(f->data, statusword);
    ncp_put_le32(f->data + 2, (uint32_t)actual);
}

int ncp_tpdo1_decode(const struct ncp_can_frame *f, uint16_t *statusword,
                     int32_t *actual)
{
    if (f->len < 6)
        return -1;
    *statusword = ncp_get_le16(f->data);
    *actual = (int32_t)ncp_get_le32(f->data + 2);
    return 0;
}

void ncp_emcy_frame(struct ncp_can_frame *f, uint8_t node, const struct ncp_emcy *e)
{
    frame_init(f, NCP_COB_EMCY + node, 8);
    ncp_put_le16(f->data, e->code);
    f->data[2] = e->reg;
    memcpy(f->data + 3, e->vendor, 5);
}

int ncp_emcy_decode(const struct ncp_can_frame *f, struct ncp_emcy *e)
{
    if (f->len < 3)
        return -1;
    memset(e, 0, sizeof *e);
    e->code = ncp_get_le16(f->data);
    e->reg = f->data[2];
    memcpy(e->vendor, f->data + 3, f->len > 3 ? (size_t)(f->len - 3) : 0);
    return 0;
}

/* Codes a CiA 402 servo commonly sends; the rest by their CiA 301 class. */
const char *ncp_emcy_code_text(uint16_t code)
{
    static const struct { uint16_t code; const char *text; } known[] = {
        {0x0000, "error reset / no error"},
        {0x2310, "continuous over-current"},
        {0x2320, "short circuit at the outputs"},
        {0x3210, "DC link over-voltage"},
        {0x3220, "DC link under-voltage"},
        {0x4310, "drive over-temperature"},
        {0x5530, "EEPROM / data storage fault"},
        {0x7121, "motor blocked"},
        {0x7305, "incremental encoder fault"},
        {0x8110, "CAN overrun (frames lost)"},
        {0x8120, "CAN in error passive mode"},
        {0x8130, "life guard or heartbeat error"},
        {0x8140, "recovered from bus off"},
        {0x8611, "following error"},
        {0x8250, "RPDO timeout"},
        {0x8612, "reference limit"},
        {0x8700, "sync controller: SYNC lost"},
    };
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
        if (known[i].code == code)
            return known[i].text;
    switch (code >> 12) {
    case 0x1: return "generic error";
    case 0x2: return "current error";
    case 0x3: return "voltage error";
    case 0x4: return "temperature error";
    case 0x5: return "device hardware error";
    case 0x6: return "device software error";
    case 0x7: return "additional modules error";
    case 0x8: return "monitoring error";
    case 0x9: return "external error";
    case 0xF: return "device specific error";
    default: return "unclassified error";
    }
}

void ncp_emcy_describe(const struct ncp_emcy *e, char *buf, size_t len)
{
    static const char *const bits[8] = {"generic", "current", "voltage", "temperature",
                                        "communication", "device profile", "reserved",
                                        "manufacturer"};
    int n = snprintf(buf, len, "error code 0x%04X %s; error register 0x%02X", e->code,
                     ncp_emcy_code_text(e->code), e->reg);
    const char *sep = ": ";
    for (int b = 0; b < 8 && n >= 0 && (size_t)n < len; b++) {
        if (!(e->reg & (1u << b)))
            continue;
        n += snprintf(buf + n, len - (size_t)n, "%s%s", sep, bits[b]);
        sep = ", ";
    }
}
