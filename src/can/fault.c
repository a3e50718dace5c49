/* Text of a master fault, and the interpolation period encoding: the pieces of
 * the master that need no bus. */
#include <stdio.h>
#include <string.h>

#include "ncpar/can.h"

int ncp_co_interp_period(long period_us, uint8_t *value, int8_t *index)
{
    /* 10^-3 s first: drives commonly understand ms best */
    long unit = 1000;
    for (int8_t e = -3; e >= -6; e--, unit /= 10) {
        if (period_us > 0 && period_us % unit == 0 && period_us / unit <= 255) {
            *value = (uint8_t)(period_us / unit);
            *index = e;
            return 0;
        }
    }
    return -1;
}

static void describe_state(const struct ncp_co_fault *f, char *buf, size_t len)
{
    char code[48];
    if (f->error_code >= 0)
        snprintf(code, sizeof code, "0x%04X", (unsigned)f->error_code);
    else
        snprintf(code, sizeof code, "unreadable");
    snprintf(buf, len,
             "node %u: drive left Operation enabled: now %s (statusword 0x6041 = 0x%04X, "
             "error code 0x603F = %s)",
             f->node, ncp_cia402_state_name(ncp_cia402_state(f->statusword)), f->statusword,
             code);
}

static void describe_homing(const struct ncp_co_fault *f, char *buf, size_t len)
{
    unsigned sw = f->statusword;
    switch (f->home_why) {
    case NCP_CH_WHY_ERROR:
        snprintf(buf, len,
                 "node %u: the drive's own homing (method %d) ended in a homing error "
                 "(statusword 0x6041 = 0x%04X, bit 13) after %.1f s; the axis is not homed: "
                 "check its home switch, index pulse and HOME_METHOD",
                 f->node, f->home_method, sw, (double)f->home_ms / 1000);
        break;
    case NCP_CH_WHY_TIMEOUT:
        snprintf(buf, len,
                 "node %u: the drive's own homing (method %d) did not end within %.1f s "
                 "(statusword 0x6041 = 0x%04X: %s); the axis is not homed: is its home "
                 "switch within reach at HOME_SEARCH_VEL?",
                 f->node, f->home_method, (double)f->home_ms / 1000, sw,
                 (sw & NCP_402_SW_HOMING_ATTAINED) ? "homing attained, target not reached"
                                                   : "homing still in progress");
        break;
    default:
        snprintf(buf, len, "%s (the drive's own homing, method %d); the axis is not homed",
                 f->text, f->home_method);
        break;
    }
}

void ncp_co_fault_describe(const struct ncp_co_fault *f, const char *ifname, char *buf,
                           size_t len)
{
    char why[160];
    unsigned hb = NCP_COB_HEARTBEAT + f->node;
    switch (f->kind) {
    case NCP_CO_FAULT_NONE:
        snprintf(buf, len, "no fault");
        break;
    case NCP_CO_FAULT_EMCY:
        ncp_emcy_describe(&f->emcy, why, sizeof why);
        snprintf(buf, len, "node %u: EMCY (0x%03X): %s", f->node, NCP_COB_EMCY + f->node, why);
        break;
    case NCP_CO_FAULT_HEARTBEAT:
        if (f->hb_age_ms < 0)
            snprintf(buf, len, "node %u: heartbeat (0x%03X) lost: none received within %d ms",
                     f->node, hb, f->hb_timeout_ms);
        else
            snprintf(buf, len,
                     "node %u: heartbeat (0x%03X) lost: last one %lld ms ago, timeout %d ms "
                     "(last state %s)",
                     f->node, hb, (long long)f->hb_age_ms, f->hb_timeout_ms,
                     ncp_nmt_state_name(f->hb_state));
        break;
    case NCP_CO_FAULT_NMT:
        snprintf(buf, len, "node %u: heartbeat (0x%03X) reports NMT state %s, not operational",
                 f->node, hb, ncp_nmt_state_name(f->hb_state));
        break;
    case NCP_CO_FAULT_STATE:
        describe_state(f, buf, len);
        break;
    case NCP_CO_FAULT_BUS:
        if (f->err)
            snprintf(buf, len, "CAN %s: cannot send frame 0x%03X (node %u): %s", ifname,
                     (unsigned)f->cob, f->node, strerror(f->err));
        else
            snprintf(buf, len,
                     "CAN %s: transmit queue full for 50 periods, frame 0x%03X (node %u) "
                     "not sent",
                     ifname, (unsigned)f->cob, f->node);
        break;
    case NCP_CO_FAULT_START:
        snprintf(buf, len, "%s", f->text);
        break;
    case NCP_CO_FAULT_HOMING:
        describe_homing(f, buf, len);
        break;
    }
}
