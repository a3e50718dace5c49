/* The NCK's states and its events' kinds by name, as cnc-ctl, the status
 * JSON, the panel and the INI speak of them; the constants are status_t's
 * and event_t's. */
#include <stddef.h>
#include <string.h>

#include "ncp_ax_status_t.h"
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

static const char *const estimate_names[] = {
    [NCP_STATUS_T_EST_NONE] = "none",     [NCP_STATUS_T_EST_RUNNING] = "running",
    [NCP_STATUS_T_EST_DONE] = "done",     [NCP_STATUS_T_EST_FAILED] = "failed",
    [NCP_STATUS_T_EST_CANCELLED] = "cancelled",
};

const char *ncp_msg_estimate_name(int state)
{
    return state >= 0 && state < (int)(sizeof estimate_names / sizeof estimate_names[0])
               ? estimate_names[state] : NULL;
}

static const char *const llc_names[] = {
    [NCP_AX_STATUS_T_WAITING] = "waiting", [NCP_AX_STATUS_T_RUNNING] = "running",
    [NCP_AX_STATUS_T_STOPPING] = "stopping", [NCP_AX_STATUS_T_STOPPED] = "stopped",
    [NCP_AX_STATUS_T_FAULT] = "fault",     [NCP_AX_STATUS_T_DONE] = "done",
};

const char *ncp_msg_llc_state_name(int state)
{
    if (state == -1)
        return "unheard";
    return state >= 0 && state < (int)(sizeof llc_names / sizeof llc_names[0])
               ? llc_names[state] : NULL;
}

static const char *const llc_errors[] = {
    [NCP_STATUS_T_LLC_ERR_NONE] = "",
    [NCP_STATUS_T_LLC_ERR_HLC_STOP] = "stopped by the HLC",
    [NCP_STATUS_T_LLC_ERR_HLC_SILENT] = "the HLC's heartbeat lost",
    [NCP_STATUS_T_LLC_ERR_LOST] = "setpoints lost",
    [NCP_STATUS_T_LLC_ERR_FERROR] = "following error",
    [NCP_STATUS_T_LLC_ERR_MISSING] = "a record missing",
    [NCP_STATUS_T_LLC_ERR_SIGNAL] = "stopped by a signal",
    [NCP_STATUS_T_LLC_ERR_PROGRAM] = "its NCK stopped on the program",
    [NCP_STATUS_T_LLC_ERR_CLOCK] = "the clocks apart",
    [NCP_STATUS_T_LLC_ERR_DRIVE] = "drive fault",
    [NCP_STATUS_T_LLC_ERR_UNHEARD] = "unheard (killed or cut off)",
    [NCP_STATUS_T_LLC_ERR_OTHER] = "stopped on its own",
};

const char *ncp_msg_llc_error_name(int error)
{
    return error >= 0 && error < (int)(sizeof llc_errors / sizeof llc_errors[0])
               ? llc_errors[error] : NULL;
}

static const char *const event_kinds[] = {
    [NCP_EVENT_T_INFO] = "info",   [NCP_EVENT_T_MSG] = "msg",     [NCP_EVENT_T_DEBUG] = "debug",
    [NCP_EVENT_T_PRINT] = "print", [NCP_EVENT_T_ERROR] = "error", [NCP_EVENT_T_FAULT] = "fault",
};

const char *ncp_msg_event_kind_name(int kind)
{
    return kind >= 0 && kind < (int)(sizeof event_kinds / sizeof event_kinds[0])
               ? event_kinds[kind] : NULL;
}
