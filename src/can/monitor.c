/* The master's picture of each drive, fed by TPDO1, heartbeat and EMCY. */
#include "ncpar/can.h"

void ncp_co_node_init(struct ncp_co_node *node, uint8_t id)
{
    *node = (struct ncp_co_node){.id = id, .last_hb_ms = -1};
}

size_t ncp_co_filter_ids(const struct ncp_co_node *nodes, size_t n, uint32_t *ids,
                         size_t max)
{
    size_t k = 0;
    for (size_t i = 0; i < n && k + 5 <= max; i++) {
        ids[k++] = NCP_COB_SDO_TX + nodes[i].id;
        ids[k++] = NCP_COB_TPDO1 + nodes[i].id;
        ids[k++] = NCP_COB_TPDO2 + nodes[i].id;
        ids[k++] = NCP_COB_EMCY + nodes[i].id;
        ids[k++] = NCP_COB_HEARTBEAT + nodes[i].id;
    }
    return k;
}

enum ncp_co_event ncp_co_track(struct ncp_co_node *nodes, size_t n,
                               const struct ncp_can_frame *f, int64_t now_ms)
{
    uint32_t fn = f->id & 0x780u, id = f->id & 0x7Fu;
    for (size_t i = 0; i < n; i++) {
        struct ncp_co_node *nd = &nodes[i];
        if (nd->id != id)
            continue;
        if (fn == NCP_COB_TPDO1 && ncp_tpdo1_decode(f, &nd->statusword, &nd->actual) == 0) {
            nd->tpdos++;
            return NCP_CO_TPDO;
        }
        if (fn == NCP_COB_TPDO2 && f->len >= 4) {
            nd->din = (uint32_t)f->data[0] | (uint32_t)f->data[1] << 8 |
                      (uint32_t)f->data[2] << 16 | (uint32_t)f->data[3] << 24;
            nd->dins++;
            return NCP_CO_DIN;
        }
        if (fn == NCP_COB_HEARTBEAT && f->len >= 1) {
            nd->last_hb_ms = now_ms;
            nd->hb_state = f->data[0] & 0x7Fu;
            return NCP_CO_HEARTBEAT;
        }
        if (fn == NCP_COB_EMCY && id != 0 && ncp_emcy_decode(f, &nd->emcy) == 0) {
            nd->emcys++;
            return NCP_CO_EMCY;
        }
    }
    return NCP_CO_NONE;
}

int ncp_co_check_heartbeat(const struct ncp_co_node *node, int64_t now_ms,
                           int64_t since_ms, int timeout_ms, struct ncp_diag *d)
{
    int64_t last = node->last_hb_ms >= 0 ? node->last_hb_ms : since_ms;
    if (now_ms - last <= timeout_ms)
        return NCP_OK;
    if (node->last_hb_ms < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: heartbeat (0x%03X) lost: none received within %d ms",
                            node->id, NCP_COB_HEARTBEAT + node->id, timeout_ms);
    return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                        "node %u: heartbeat (0x%03X) lost: last one %lld ms ago, "
                        "timeout %d ms (last state %s)",
                        node->id, NCP_COB_HEARTBEAT + node->id,
                        (long long)(now_ms - last), timeout_ms,
                        ncp_nmt_state_name(node->hb_state));
}
