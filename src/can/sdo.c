/* Expedited SDO (CiA 301): frames, abort codes, and the blocking client. */
#include <string.h>
#include <time.h>

#include "bytes.h"
#include "ncpar/can.h"
#include "ncpar/clock.h"

/* Command specifiers of byte 0. */
#define CS_UPLOAD_REQ     0x40u
#define CS_UPLOAD_RESP    0x40u /* | expedited, size bits */
#define CS_DOWNLOAD_REQ   0x20u
#define CS_DOWNLOAD_RESP  0x60u
#define CS_ABORT          0x80u
#define CS_EXPEDITED_SIZE 0x03u /* e=1, s=1 */

static void sdo_frame(struct ncp_can_frame *f, uint32_t id, uint8_t cs, uint16_t index,
                      uint8_t sub)
{
    memset(f, 0, sizeof *f);
    f->id = id;
    f->len = 8;
    f->data[0] = cs;
    ncp_put_le16(f->data + 1, index);
    f->data[3] = sub;
}

static uint8_t size_bits(unsigned size)
{
    unsigned n = (size >= 1 && size <= 4) ? size : 4;
    return (uint8_t)((4u - n) << 2 | CS_EXPEDITED_SIZE);
}

void ncp_sdo_upload_req(struct ncp_can_frame *f, uint8_t node, uint16_t index, uint8_t sub)
{
    sdo_frame(f, NCP_COB_SDO_RX + node, CS_UPLOAD_REQ, index, sub);
}

void ncp_sdo_download_req(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                          uint8_t sub, uint32_t value, unsigned size)
{
    sdo_frame(f, NCP_COB_SDO_RX + node, (uint8_t)(CS_DOWNLOAD_REQ | size_bits(size)), index,
              sub);
    ncp_put_le32(f->data + 4, value);
}

void ncp_sdo_upload_resp(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                         uint8_t sub, uint32_t value, unsigned size)
{
    sdo_frame(f, NCP_COB_SDO_TX + node, (uint8_t)(CS_UPLOAD_RESP | size_bits(size)), index,
              sub);
    ncp_put_le32(f->data + 4, value);
}

void ncp_sdo_download_resp(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                           uint8_t sub)
{
    sdo_frame(f, NCP_COB_SDO_TX + node, CS_DOWNLOAD_RESP, index, sub);
}

void ncp_sdo_abort_frame(struct ncp_can_frame *f, uint32_t cob, uint16_t index,
                         uint8_t sub, uint32_t code)
{
    sdo_frame(f, cob, CS_ABORT, index, sub);
    ncp_put_le32(f->data + 4, code);
}

const char *ncp_sdo_abort_text(uint32_t code)
{
    static const struct { uint32_t code; const char *text; } t[] = {
        {0x05030000, "toggle bit not alternated"},
        {0x05040000, "SDO protocol timed out"},
        {0x05040001, "command specifier not valid or unknown"},
        {0x05040005, "out of memory"},
        {0x06010000, "unsupported access to an object"},
        {0x06010001, "attempt to read a write-only object"},
        {0x06010002, "attempt to write a read-only object"},
        {0x06020000, "object does not exist in the object dictionary"},
        {0x06040041, "object cannot be mapped to the PDO"},
        {0x06040042, "mapped objects would exceed the PDO length"},
        {0x06040043, "general parameter incompatibility"},
        {0x06040047, "general internal incompatibility in the device"},
        {0x06060000, "access failed due to a hardware error"},
        {0x06070010, "data type or length does not match"},
        {0x06070012, "data type does not match, length too high"},
        {0x06070013, "data type does not match, length too low"},
        {0x06090011, "sub-index does not exist"},
        {0x06090030, "invalid value for parameter"},
        {0x06090031, "value of parameter too high"},
        {0x06090032, "value of parameter too low"},
        {0x08000000, "general error"},
        {0x08000020, "data cannot be transferred or stored"},
        {0x08000021, "data cannot be transferred or stored: local control"},
        {0x08000022, "data cannot be transferred or stored: present device state"},
        {0x08000023, "no object dictionary present"},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        if (t[i].code == code)
            return t[i].text;
    return "unknown abort code";
}

/* Sends req and waits for the server's frame about the same object. */
static int sdo_exchange(struct ncp_can_bus *bus, uint8_t node, const struct ncp_can_frame *req,
                        struct ncp_can_frame *resp, int timeout_ms, const char *what,
                        uint32_t *abort, struct ncp_diag *d)
{
    uint16_t index = ncp_get_le16(req->data + 1);
    uint8_t sub = req->data[3];
    if (abort)
        *abort = 0;
    memset(resp, 0, sizeof *resp);
    int rc = ncp_can_send(bus, req, d);
    if (rc != NCP_OK)
        return rc;
    int64_t deadline = ncp_mono_ms() + timeout_ms;
    for (;;) {
        int64_t left = deadline - ncp_mono_ms();
        if (left <= 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "node %u: SDO %s 0x%04X:%02X: no answer within %d ms",
                                node, what, index, sub, timeout_ms);
        int r = ncp_can_recv(bus, resp, (int)left, d);
        if (r < 0)
            return NCP_ERR_IO;
        if (r == 0 || resp->id != NCP_COB_SDO_TX + node || resp->len < 8)
            continue;
        if (ncp_get_le16(resp->data + 1) != index || resp->data[3] != sub)
            continue;
        if (resp->data[0] == CS_ABORT) {
            uint32_t code = ncp_get_le32(resp->data + 4);
            if (abort)
                *abort = code;
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "node %u: SDO %s 0x%04X:%02X aborted: 0x%08X %s", node,
                                what, index, sub, code, ncp_sdo_abort_text(code));
        }
        return NCP_OK;
    }
}

int ncp_sdo_read(struct ncp_can_bus *bus, uint8_t node, uint16_t index, uint8_t sub,
                 uint32_t *value, int timeout_ms, uint32_t *abort, struct ncp_diag *d)
{
    struct ncp_can_frame req, resp;
    ncp_sdo_upload_req(&req, node, index, sub);
    int rc = sdo_exchange(bus, node, &req, &resp, timeout_ms, "read", abort, d);
    if (rc != NCP_OK)
        return rc;
    uint8_t cs = resp.data[0];
    if ((cs & 0xE0u) != CS_UPLOAD_RESP)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: SDO read 0x%04X:%02X: unexpected answer 0x%02X", node,
                            index, sub, cs);
    if (!(cs & 0x02u))
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: SDO read 0x%04X:%02X: value longer than 4 bytes "
                            "(segmented transfer not supported)",
                            node, index, sub);
    uint32_t v = ncp_get_le32(resp.data + 4);
    if (cs & 0x01u) {
        unsigned n = 4u - ((cs >> 2) & 3u);
        if (n < 4)
            v &= (1u << (8 * n)) - 1u;
    }
    *value = v;
    return NCP_OK;
}

int ncp_sdo_write(struct ncp_can_bus *bus, uint8_t node, uint16_t index, uint8_t sub,
                  uint32_t value, unsigned size, int timeout_ms, uint32_t *abort,
                  struct ncp_diag *d)
{
    struct ncp_can_frame req, resp;
    ncp_sdo_download_req(&req, node, index, sub, value, size);
    int rc = sdo_exchange(bus, node, &req, &resp, timeout_ms, "write", abort, d);
    if (rc != NCP_OK)
        return rc;
    if (resp.data[0] != CS_DOWNLOAD_RESP)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: SDO write 0x%04X:%02X: unexpected answer 0x%02X",
                            node, index, sub, resp.data[0]);
    return NCP_OK;
}
