/* ADCAI's DP2 and DP3 on the HLC: the ADCAI chain taps every setpoint it
 * emits (with the rough record it started, if it started one); the position
 * loop plays them one per period at full rate. Each period this finds the
 * tap of the setpoint the loop plays, by its position in nm (at full rate
 * the loop plays the stream's samples as they are), and when that setpoint
 * starts a rough period, sends the record stamped with this period: the
 * LLCs run their stages on the same grid as the HLC.
 *
 * When the loop time-scales (feed hold, an override, the end of --for) its
 * setpoints lie between the stream's: then the stream goes on at one sample a
 * period as long as it was moving, so the LLCs follow the program, not the
 * scaling, until the HLC's heartbeat says done or stop (the same limit as
 * ADCBI's DP4). At rest, a sample that does not match is one the loop has
 * not reached yet (a move after a wait): it waits. */
#include "lcm_ai.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TAP_RING 4096   /* setpoints: more than [PLANNER] SETPOINT_RING ahead */

int lcm_ai_init(struct lcm_ai *x, int dp, const struct ncp_machine_cfg *cfg)
{
    memset(x, 0, sizeof *x);
    x->dp = dp;
    for (int j = 0; j < NCP_AXES; j++)
        if (cfg->axis_mask & NCP_AXIS_BIT(j))
            x->axis[x->n++] = j;
    ncp_dist_ai_init();
    return ncp_spsc_init(&x->tapped, sizeof(struct ncp_adcai_tap), TAP_RING);
}

void lcm_ai_free(struct lcm_ai *x)
{
    ncp_spsc_destroy(&x->tapped);
}

void lcm_ai_push(struct lcm_ai *x, const struct ncp_adcai_tap *t)
{
    if (ncp_spsc_push(&x->tapped, t) != 0)
        x->overflow++;
}

static void send(struct lcm_ai *x, struct ncp_msg *m, int64_t t, const struct ncp_adcai_tap *e)
{
    struct ncp_dist_ai r = { x->seq++, NCP_DIST_HLC_ID, t, (int8_t)e->stop, (int8_t)x->n, { 0 } };
    for (int i = 0; i < x->n; i++)
        r.sum_nm[i] = x->dp == 2 ? e->rough[x->axis[i]] : e->accdec[x->axis[i]];
    uint8_t buf[128];
    int n = ncp_dist_encode_ai(buf, sizeof buf, x->dp, &r);
    if (n > 0 && ncp_msg_publish(m, x->dp == 2 ? NCP_DIST_CH_ROUGH : NCP_DIST_CH_ACCDEC_AI, buf,
                                 (size_t)n) == 0) {
        x->sent++;
        x->bytes = n;
    }
}

static int matches(const struct lcm_ai *x, const struct ncp_adcai_tap *e,
                   const double cmd[NCP_AXES])
{
    for (int i = 0; i < x->n; i++) {
        int j = x->axis[i];
        if ((double)e->pos[j] != nearbyint(cmd[j] * NCP_ADCAI_UNITS_PER_MM))
            return 0;
    }
    return 1;
}

void lcm_ai_cycle(struct lcm_ai *x, struct ncp_msg *m, int64_t t, const double cmd[NCP_AXES])
{
    if (!x->have_front)
        x->have_front = ncp_spsc_pop(&x->tapped, &x->front) == 0;
    if (!x->have_front)
        return;
    if (!matches(x, &x->front, cmd)) {
        if (!x->last_moved)
            return;
        x->unmatched++;
    }
    if (x->front.start)
        send(x, m, t, &x->front);
    x->last_moved = 0;
    for (int i = 0; i < x->n && x->primed; i++)
        x->last_moved |= x->front.pos[x->axis[i]] != x->last_pos[x->axis[i]];
    x->primed = 1;
    memcpy(x->last_pos, x->front.pos, sizeof x->last_pos);
    x->have_front = 0;
}

void lcm_ai_report(const struct lcm_ai *x)
{
    const char *ch = x->dp == 2 ? NCP_DIST_CH_ROUGH : NCP_DIST_CH_ACCDEC_AI;
    fprintf(stderr, "lcm: DP %d (ADCAI): %llu %s messages of %d bytes (all %d axes; %d with the "
                    "LCM header), one a rough period; %llu setpoints played off the stream "
                    "(time-scaled), %llu lost to a full tap ring\n",
            x->dp, (unsigned long long)x->sent, x->dp == 2 ? "roughIPObuf" : "ACCDECbuf", x->bytes,
            x->n, x->bytes + 8 + (int)strlen(ch) + 1, (unsigned long long)x->unmatched,
            (unsigned long long)x->overflow);
}
