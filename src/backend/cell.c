/* The channels of a channels INI against their backends: each channel's
 * axes are what its backend drives, and no two channels drive one thing.
 * Two channels on one CAN interface would each send SYNC on that bus as its
 * master; two on one LCM URL would each send the HLC's channels (NCP_HLC_*)
 * that every LLC there takes as its own. Both are refused before anything
 * is opened, naming the channels INI's line. */
#include "ncpar/backend.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the line that chose the backend: BACKEND, else the section's */
static unsigned backend_line(const struct ncp_cell_channel *ch)
{
    return ch->backend_line ? ch->backend_line : ch->line;
}

int ncp_backend_cell_channel(const struct ncp_cell_channel *ch, const struct ncp_machine_cfg *cfg,
                             struct ncp_diag *d)
{
    struct ncp_diag e;
    memset(&e, 0, sizeof e);
    if (cfg->backend == NCP_BACKEND_SOCKETCAN && ncp_socketcan_check_cfg(cfg, &e) != NCP_OK) {
        const char *why = e.msg;
        if (!strncmp(why, "socketcan backend: ", 19))
            why += 19;
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, backend_line(ch), 0,
                            "[CHANNEL_%d] socketcan: its machine INI's axes must be its CAN "
                            "drives: %.160s", ch->num, why);
    }
    if (cfg->backend == NCP_BACKEND_LCM && cfg->nck == NCP_NCK_ADCAI &&
        !ncp_dist_adcai_dp(cfg->lcm.dp))
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, ch->dp_line ? ch->dp_line : backend_line(ch), 0,
                            "[CHANNEL_%d] lcm: DP %d, but its machine INI's [PLANNER] NCK = "
                            "adcai has DP 1-4 (its fine setpoints are DP 4)", ch->num,
                            cfg->lcm.dp);
    return NCP_OK;
}

/* The LCM group and port the channel's LLCs hear it on; -1 for a URL that
 * does not parse (its backend says why when it opens). */
static int lcm_where(const struct ncp_machine_cfg *cfg, struct ncp_msg_url *u)
{
    const char *url = cfg->lcm.url;
    if (!url[0])
        url = getenv("LCM_DEFAULT_URL");
    if (!url || !url[0])
        url = NCP_MSG_DEFAULT_URL;
    struct ncp_diag e;
    memset(&e, 0, sizeof e);
    return ncp_msg_parse_url(url, u, &e) == NCP_OK ? 0 : -1;
}

static int shared_can(const struct ncp_cell_channel *a, const struct ncp_machine_cfg *ca,
                      const struct ncp_cell_channel *b, const struct ncp_machine_cfg *cb,
                      struct ncp_diag *d)
{
    if (strcmp(ca->can.interface, cb->can.interface) != 0)
        return NCP_OK;
    for (int i = 0; i < NCP_AXES; i++)
        for (int j = 0; j < NCP_AXES; j++)
            if ((ca->axis_mask & NCP_AXIS_BIT(i)) && (cb->axis_mask & NCP_AXIS_BIT(j)) &&
                ca->axis[i].node_id == cb->axis[j].node_id)
                return ncp_diag_set(d, NCP_ERR_SEMANTIC, backend_line(b), 0,
                                    "[CHANNEL_%d] socketcan: CAN node %d on %s is channel %d's "
                                    "axis %c and channel %d's axis %c: a drive belongs to one "
                                    "channel", b->num, ca->axis[i].node_id, ca->can.interface,
                                    a->num, NCP_AXIS_LETTERS[i], b->num, NCP_AXIS_LETTERS[j]);
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, backend_line(b), 0,
                        "[CHANNEL_%d] socketcan: channels %d and %d on one CAN interface %s: "
                        "each channel masters its bus (its own SYNC); give each channel its "
                        "own interface (BACKEND = socketcan:IFACE)", b->num, a->num, b->num,
                        ca->can.interface);
}

static int shared_lcm(const struct ncp_cell_channel *a, const struct ncp_machine_cfg *ca,
                      const struct ncp_cell_channel *b, const struct ncp_machine_cfg *cb,
                      struct ncp_diag *d)
{
    struct ncp_msg_url ua, ub;
    if (lcm_where(ca, &ua) || lcm_where(cb, &ub) || strcmp(ua.group, ub.group) != 0 ||
        ua.port != ub.port)
        return NCP_OK;
    unsigned both = ca->axis_mask & cb->axis_mask;
    for (int j = 0; j < NCP_AXES; j++)
        if (both & NCP_AXIS_BIT(j))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, backend_line(b), 0,
                                "[CHANNEL_%d] lcm: the LLC of axis %c on udpm://%s:%u would be "
                                "channel %d's and channel %d's: an LLC belongs to one channel",
                                b->num, NCP_AXIS_LETTERS[j], ua.group, (unsigned)ua.port,
                                a->num, b->num);
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, backend_line(b), 0,
                        "[CHANNEL_%d] lcm: channels %d and %d on one LCM URL udpm://%s:%u: "
                        "every LLC there hears both HLCs' setpoints; give each channel's "
                        "machine INI its own [LCM] URL", b->num, a->num, b->num, ua.group,
                        (unsigned)ua.port);
}

int ncp_backend_cell_shared(const struct ncp_cell *cell, const struct ncp_machine_cfg *const cfgs[],
                            struct ncp_diag *d)
{
    for (int j = 1; j < cell->n; j++)
        for (int i = 0; i < j; i++) {
            const struct ncp_machine_cfg *ci = cfgs[i], *cj = cfgs[j];
            if (ci->backend != cj->backend || ci->backend == NCP_BACKEND_SIM)
                continue;
            int rc = ci->backend == NCP_BACKEND_SOCKETCAN
                         ? shared_can(&cell->ch[i], ci, &cell->ch[j], cj, d)
                         : shared_lcm(&cell->ch[i], ci, &cell->ch[j], cj, d);
            if (rc != NCP_OK)
                return rc;
        }
    return NCP_OK;
}
