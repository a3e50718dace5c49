/* [SCHED] of the machine INI. */
#include "ncpar/sched.h"
#include "ncpar/num.h"

#include <stdio.h>
#include <stdlib.h>
#include <strings.h>

void ncp_sched_cfg_default(struct ncp_sched_cfg *c)
{
    c->strategy = NCP_SCHED_NONE;
    c->period_ms = 10;
    c->floor = 1;
    c->trace_rings = 0;
}

const char *ncp_sched_strategy_name(enum ncp_sched_strategy s)
{
    return s == NCP_SCHED_STATIC ? "static" : s == NCP_SCHED_DATAFLOW ? "dataflow" : "none";
}

int ncp_sched_ini_key(struct ncp_sched_cfg *c, const char *k, const char *v, char *why,
                      size_t len)
{
    if (!strcasecmp(k, "STRATEGY")) {
        if (!strcasecmp(v, "static"))
            c->strategy = NCP_SCHED_STATIC;
        else if (!strcasecmp(v, "dataflow"))
            c->strategy = NCP_SCHED_DATAFLOW;
        else if (!strcasecmp(v, "none"))
            c->strategy = NCP_SCHED_NONE;
        else
            return snprintf(why, len, "static, dataflow or none"), -1;
        return 1;
    }
    if (!strcasecmp(k, "PERIOD_MS"))
        return ncp_num_int(v, 1, 1000, &c->period_ms) ? snprintf(why, len, "1..1000 ms"), -1 : 1;
    if (!strcasecmp(k, "PRIORITY_MIN"))
        return ncp_num_int(v, 1, 97, &c->floor) ? snprintf(why, len, "1..97 (SCHED_FIFO)"), -1 : 1;
    if (!strcasecmp(k, "TRACE_RINGS"))
        return ncp_num_int(v, 0, 1, &c->trace_rings) ? snprintf(why, len, "0 or 1"), -1 : 1;
    return 0;
}
