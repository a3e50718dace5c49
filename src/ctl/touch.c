/* cnc-ctl touch-off and touch-off-tool: the operator's touch-off as LinuxCNC's
 * AXIS does it, through MDI (G10 L20 for a work offset, G10 L10 then G43
 * for the tool in the spindle), so the NCK's own rules decide, with its
 * reasons, when it may happen (not while a program runs). Each line is
 * waited for, so the offset is in force when cnc-ctl returns. */
#include <stdio.h>
#include <string.h>

#include "ctl.h"

static int mdi_and_wait(struct ctl *c, const char *line, const char *what)
{
    ncp_command_t cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.kind = NCP_COMMAND_T_MDI;
    snprintf((char *)cmd.text, sizeof cmd.text, "%s", line);
    int rc = ctl_command(c, &cmd);
    return rc == CTL_OK ? ctl_wait_done(c, NCP_STATUS_T_MDI, what) : rc;
}

int ctl_touch_off(struct ctl *c, char axis, double value, int system)
{
    char line[96];
    snprintf(line, sizeof line, "G10 L20 P%d %c%.17g", system, axis, value);
    return mdi_and_wait(c, line, "the touch-off");
}

int ctl_touch_off_tool(struct ctl *c, char axis, double value)
{
    int rc = ctl_next_status(c, c->timeout);
    if (rc == CTL_NO_ANSWER)
        ctl_no_answer("status", c->timeout);
    if (rc != CTL_OK)
        return rc < 0 ? CTL_NO_ANSWER : rc;
    int tool = c->status.tool;
    if (tool <= 0) {
        fprintf(stderr, "cnc-ctl: rejected: no tool in the spindle (T0): touch-off-tool sets "
                        "the offset of the tool in the spindle (M6 one first)\n");
        return CTL_REJECTED;
    }
    char line[96];
    snprintf(line, sizeof line, "G10 L10 P%d %c%.17g", tool, axis, value);
    rc = mdi_and_wait(c, line, "the tool touch-off");
    /* the new offset in force, as AXIS does after it */
    return rc == CTL_OK ? mdi_and_wait(c, "G43", "G43 after the tool touch-off") : rc;
}
