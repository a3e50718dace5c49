/* DP1 at the HLC, either variant: no blocks and no records go out, only the
 * program to run (by path, on one host, with its size and hash: program_t)
 * and, through lcm_tx with nothing to send, the periods the path leaves
 * each standstill. Each LLC runs the NCK of its INI's variant on the
 * program itself and follows those marks (src/axis/dp1.c, dp1_ai.c). The HLC runs its own NCK as well:
 * it decides when motion starts (spindle at speed, a pause) and keeps the
 * trace and summary of a central run. */
#include "lcm_tx.h"

#include <stdio.h>
#include <string.h>

int lcm_dp1_init(struct lcm_dp1 *p, const struct ncp_lcm_cfg *c)
{
    memset(p, 0, sizeof *p);
    p->msg.hash = (int64_t)ncp_dist_file_hash(c->program, &p->msg.size);
    p->msg.sender = NCP_DIST_HLC_ID;
    snprintf((char *)p->msg.path, sizeof p->msg.path, "%s", c->program);
    snprintf((char *)p->msg.tool_table, sizeof p->msg.tool_table, "%s", c->tool_table);
    snprintf((char *)p->msg.sub_path, sizeof p->msg.sub_path, "%s", c->sub_path);
    return p->msg.size < 0 ? -1 : 0;
}

void lcm_dp1_send(struct lcm_dp1 *p, struct ncp_msg *m)
{
    p->msg.seq = p->seq++;
    uint8_t buf[1024];
    int n = ncp_program_t_encode(buf, 0, sizeof buf, &p->msg);
    if (n > 0 && ncp_msg_publish(m, NCP_DIST_CH_PROGRAM, buf, (size_t)n) == 0)
        p->bytes = n;
}
