/* The NCK's states by name, as cnc-ctl, the status JSON and the INI speak of
 * them; the constants are status_t's. */
#include <stddef.h>
#include <string.h>

#include "ncpar/msg.h"

static const char *const state_names[] = {
    [NCP_STATUS_T_IDLE] = "idle",         [NCP_STATUS_T_RUNNING] = "running",
    [NCP_STATUS_T_PAUSED] = "paused",     [NCP_STATUS_T_STEPPING] = "stepping",
    [NCP_STATUS_T_MDI] = "mdi",           [NCP_STATUS_T_JOGGING] = "jogging",
    [NCP_STATUS_T_HOMING] = "homing",     [NCP_STATUS_T_STOPPING] = "stopping",
    [NCP_STATUS_T_ESTOP] = "estop",       [NCP_STATUS_T_FAULT] = "fault",
};

#define N_STATES (int)(sizeof state_names / sizeof state_names[0])

const char *ncp_msg_state_name(int state)
{
    return state >= 0 && state < N_STATES ? state_names[state] : NULL;
}

int ncp_msg_state_parse(const char *name)
{
    for (int i = 0; i < N_STATES; i++)
        if (state_names[i] && strcmp(state_names[i], name) == 0)
            return i;
    return -1;
}
