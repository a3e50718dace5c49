/* cnc-ctl jog: an incremental jog is one command; a continuous one is kept
 * alive from here (KEEPALIVE every 100 ms: the NCK stops the axis when they
 * stop coming) until the operator lets go (^C, SIGTERM) or the jog has
 * ended otherwise. */
#include <stdio.h>
#include <string.h>

#include "ctl.h"

#define KEEPALIVE_S 0.1
#define ENDED_S 0.3     /* another state this long after jogging: ended */
#define NEVER_SEEN_S 1.0 /* no jogging status this long after the ACK: ended */

static void jog_cmd(ncp_command_t *cmd, int16_t kind, char axis, int dir, double speed,
                    double distance)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->kind = kind;
    cmd->text[0] = (uint8_t)axis;
    cmd->ivalue[0] = dir;
    cmd->value[0] = speed;
    cmd->value[1] = distance;
}

/* JOG_STOP for the axis, answered. */
static int stop_jog(struct ctl *c, char axis)
{
    ncp_command_t cmd;
    jog_cmd(&cmd, NCP_COMMAND_T_JOG_STOP, axis, 0, 0, 0);
    int rc = ctl_command(c, &cmd);
    /* Refused because the jog had ended meanwhile: the axis stands, as asked. */
    return rc == CTL_REJECTED ? CTL_OK : rc;
}

int ctl_jog(struct ctl *c, char axis, int dir, double speed, double distance, int wait)
{
    ncp_command_t cmd;
    jog_cmd(&cmd, NCP_COMMAND_T_JOG, axis, dir, speed, distance);
    int rc = ctl_command(c, &cmd);
    if (rc == CTL_OK && distance > 0 && wait)
        return ctl_wait_done(c, NCP_STATUS_T_JOGGING, "the jog");
    if (rc != CTL_OK || distance > 0)
        return rc;

    double acked = ctl_now(), next = acked + KEEPALIVE_S, other_since = -1;
    uint64_t seen = c->n_status;
    double last_status = acked;
    int jogging_seen = 0;
    while (!ctl_interrupted) {
        double now = ctl_now();
        if (now >= next) {
            jog_cmd(&cmd, NCP_COMMAND_T_KEEPALIVE, axis, dir, speed, 0);
            if (ctl_send(c, &cmd) != 0)
                break;
            next = (next + KEEPALIVE_S > now) ? next + KEEPALIVE_S : now + KEEPALIVE_S;
        }
        if (ctl_handle(c, next - now) != 0)
            break;
        now = ctl_now();
        if (c->n_status != seen) {
            seen = c->n_status;
            last_status = now;
            if (c->status.state == NCP_STATUS_T_JOGGING) {
                jogging_seen = 1;
                other_since = -1;
            } else if (other_since < 0) {
                other_since = now;
            }
        }
        if (other_since >= 0 && now - other_since >= ENDED_S &&
            (jogging_seen || now - acked >= NEVER_SEEN_S)) {
            const char *st = ncp_msg_state_name(c->status.state);
            fprintf(stderr, "cnc-ctl: the jog of %c has ended (the NCK is %s)\n", axis,
                    st ? st : "in an unknown state");
            return c->status.state == NCP_STATUS_T_FAULT ? CTL_FAULT : CTL_OK;
        }
        if (c->timeout > 0 && now - last_status >= c->timeout) {
            ctl_no_answer("status", c->timeout);
            (void)stop_jog(c, axis);
            return CTL_NO_ANSWER;
        }
    }
    return stop_jog(c, axis);
}
