/* What the operator is told when the machine starts to wait for them: a
 * serving NCK posts an event (and its state machine shows the pause); a
 * batch run says on stderr how it will go on. Runs on the caller's thread,
 * from the cycles the position loop reports. */
#include "nck_int.h"
#include "service_state.h"

#include <unistd.h>

const char *nck_wait_name(int wait)
{
    switch (wait) {
    case NCK_WAIT_M0: return "M0 program stop";
    case NCK_WAIT_M1: return "M1 optional stop";
    case NCK_WAIT_M60: return "M60 pallet change";
    case NCK_WAIT_TOOL: return "M6 tool change";
    case NCK_WAIT_SPINDLE: return "spindle to reach its speed";
    case NCK_WAIT_ORIENT: return "M19 spindle orientation";
    case NCK_WAIT_INPUT: return "M66 wait on an input";
    case NCK_WAIT_INDEX: return "spindle index (synchronised motion)";
    default: return "nothing";
    }
}

int nck_wait_operator(int wait)
{
    return wait == NCK_WAIT_M0 || wait == NCK_WAIT_M1 || wait == NCK_WAIT_M60 ||
           wait == NCK_WAIT_TOOL;
}

void nck_wait_began(struct nck_core *n, const struct nck_fb *fb)
{
    if (!nck_wait_operator(fb->wait)) {
        if (!n->batch && fb->wait == NCK_WAIT_INPUT)
            nck_post(n, NCP_EV_INFO, NULL, fb->wait_line, 0, "waiting: %s",
                     nck_wait_name(fb->wait));
        return;
    }
    n->svc->pauses++;
    const char *what = nck_wait_name(fb->wait);
    if (!n->batch) {
        nck_post(n, NCP_EV_INFO, NULL, fb->wait_line, 0, "paused: %s; cnc-ctl %s continues", what,
                 fb->wait == NCK_WAIT_TOOL ? "tool-changed" : "resume");
        return;
    }
    double after = n->cfg->io.auto_resume_s;
    if (n->quiet)
        return;
    if (after < 0)
        fprintf(stderr, "%sline %u: paused: %s; continues on SIGUSR1 (kill -USR1 %ld)\n",
                n->label, fb->wait_line, what, (long)getpid());
    else
        fprintf(stderr, "%sline %u: paused: %s; continues after %g s ([SIM] AUTO_RESUME_S)\n",
                n->label, fb->wait_line, what, after);
}
