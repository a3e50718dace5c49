/* The front ends' stop signals (cnc-run run, cnc-run serve). */
#include "signals.h"

#include <signal.h>
#include <string.h>

void ncp_cli_catch_stop_signals(void (*on_stop)(int))
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}
