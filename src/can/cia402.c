/* CiA 402 device control: statusword decoding, the controlword that walks a
 * drive to Operation enabled, and the drive side of the state machine (for
 * the simulated drive). */
#include "ncpar/can.h"

enum ncp_cia402_state ncp_cia402_state(uint16_t sw)
{
    /* Bits 0-3, 5, 6 select the state; bit 5 (quick stop) matters only in
     * the states where the table below masks with 0x6F. */
    if ((sw & 0x4Fu) == 0x00u) return NCP_402_NOT_READY;
    if ((sw & 0x4Fu) == 0x40u) return NCP_402_SWITCH_ON_DISABLED;
    if ((sw & 0x6Fu) == 0x21u) return NCP_402_READY_TO_SWITCH_ON;
    if ((sw & 0x6Fu) == 0x23u) return NCP_402_SWITCHED_ON;
    if ((sw & 0x6Fu) == 0x27u) return NCP_402_OPERATION_ENABLED;
    if ((sw & 0x6Fu) == 0x07u) return NCP_402_QUICK_STOP_ACTIVE;
    if ((sw & 0x4Fu) == 0x0Fu) return NCP_402_FAULT_REACTION_ACTIVE;
    if ((sw & 0x4Fu) == 0x08u) return NCP_402_FAULT;
    return NCP_402_NOT_READY;
}

const char *ncp_cia402_state_name(enum ncp_cia402_state s)
{
    switch (s) {
    case NCP_402_NOT_READY: return "Not ready to switch on";
    case NCP_402_SWITCH_ON_DISABLED: return "Switch on disabled";
    case NCP_402_READY_TO_SWITCH_ON: return "Ready to switch on";
    case NCP_402_SWITCHED_ON: return "Switched on";
    case NCP_402_OPERATION_ENABLED: return "Operation enabled";
    case NCP_402_QUICK_STOP_ACTIVE: return "Quick stop active";
    case NCP_402_FAULT_REACTION_ACTIVE: return "Fault reaction active";
    case NCP_402_FAULT: return "Fault";
    }
    return "?";
}

uint16_t ncp_cia402_step(enum ncp_cia402_state s, uint16_t prev_cw)
{
    switch (s) {
    case NCP_402_SWITCH_ON_DISABLED: return NCP_402_CW_SHUTDOWN;
    case NCP_402_READY_TO_SWITCH_ON: return NCP_402_CW_SWITCH_ON;
    case NCP_402_SWITCHED_ON:
    case NCP_402_OPERATION_ENABLED: return NCP_402_CW_ENABLE;
    case NCP_402_FAULT:
        return (prev_cw & NCP_402_CW_FAULT_RESET) ? NCP_402_CW_DISABLE
                                                  : NCP_402_CW_FAULT_RESET;
    case NCP_402_QUICK_STOP_ACTIVE:
    case NCP_402_NOT_READY:
    case NCP_402_FAULT_REACTION_ACTIVE: return NCP_402_CW_DISABLE;
    }
    return NCP_402_CW_DISABLE;
}

uint16_t ncp_cia402_statusword(enum ncp_cia402_state s)
{
    switch (s) {
    case NCP_402_NOT_READY: return 0x0000;
    case NCP_402_SWITCH_ON_DISABLED: return 0x0240;
    case NCP_402_READY_TO_SWITCH_ON: return 0x0231;
    case NCP_402_SWITCHED_ON: return 0x0233;
    case NCP_402_OPERATION_ENABLED: return 0x0237;
    case NCP_402_QUICK_STOP_ACTIVE: return 0x0217;
    case NCP_402_FAULT_REACTION_ACTIVE: return 0x021F;
    case NCP_402_FAULT: return 0x0218;
    }
    return 0;
}

enum ncp_cia402_state ncp_cia402_apply(enum ncp_cia402_state s, uint16_t cw,
                                       uint16_t prev_cw)
{
    if (s == NCP_402_FAULT)
        return ((cw & 0x80u) && !(prev_cw & 0x80u)) ? NCP_402_SWITCH_ON_DISABLED : s;
    if (s == NCP_402_NOT_READY || s == NCP_402_FAULT_REACTION_ACTIVE)
        return s;
    if ((cw & 0x02u) == 0) /* disable voltage */
        return NCP_402_SWITCH_ON_DISABLED;
    if ((cw & 0x06u) == 0x02u) /* quick stop */
        return s == NCP_402_OPERATION_ENABLED ? NCP_402_QUICK_STOP_ACTIVE
                                              : NCP_402_SWITCH_ON_DISABLED;
    if (s == NCP_402_QUICK_STOP_ACTIVE)
        return s;
    if ((cw & 0x87u) == 0x06u) /* shutdown */
        return NCP_402_READY_TO_SWITCH_ON;
    if ((cw & 0x8Fu) == 0x07u) /* switch on / disable operation */
        return s == NCP_402_SWITCH_ON_DISABLED ? s : NCP_402_SWITCHED_ON;
    if ((cw & 0x8Fu) == 0x0Fu) /* enable operation */
        return (s == NCP_402_SWITCHED_ON || s == NCP_402_OPERATION_ENABLED ||
                s == NCP_402_READY_TO_SWITCH_ON)
                   ? NCP_402_OPERATION_ENABLED
                   : s;
    return s;
}
