/* The distributed axes' last errors (the lcm backend keeps one per LLC):
 * each new one goes out once as a FAULT event naming its axis, with the
 * whole text the status has no room for (it carries a code per LLC); a
 * reset acknowledges them. One heard again after it was lost is no longer
 * homed. The serving thread's, as the backend's llcs and
 * llc_ack are. */
#include "control.h"

void nck_llcs_poll(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    if (!n->cross.be.ops || !n->cross.be.ops->llcs)
        return;
    struct ncp_llc_info l[NCP_NCK_AXES_MAX];
    int count = n->cross.be.ops->llcs(&n->cross.be, l, NCP_NCK_AXES_MAX);
    for (int k = 0; k < count; k++) {
        if (l[k].returns != s->llc_returns_told[k]) {
            /* a process started again counts from where its drive stands,
             * not from the home this NCK found: its axis homes again */
            s->llc_returns_told[k] = l[k].returns;
            s->homed[l[k].axis] = 0;
            s->changed = 1;
            nck_post(n, NCP_EV_INFO, NULL, 0, 0,
                     "axis %c's LLC is heard again: %c is no longer homed",
                     NCP_AXIS_LETTERS[l[k].axis], NCP_AXIS_LETTERS[l[k].axis]);
        }
        if (!l[k].error || l[k].error_count == s->llc_errors_told[k])
            continue;
        s->llc_errors_told[k] = l[k].error_count;
        nck_post(n, NCP_EV_FAULT, NULL, 0, 0, "axis %c's LLC, last error: %s",
                 NCP_AXIS_LETTERS[l[k].axis], l[k].error_text);
        s->changed = 1;   /* its code in the status at once */
    }
}

void nck_llcs_ack(struct ncp_nck *s)
{
    struct nck_core *n = &s->core;
    if (n->cross.be.ops && n->cross.be.ops->llc_ack)
        n->cross.be.ops->llc_ack(&n->cross.be);
}
