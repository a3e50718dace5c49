/* The front ends' signals (cnc-run parse, check, run, serve). */
#include "signals.h"
#include "outfile.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

void ncp_cli_catch_stop_signals(void (*on_stop)(int))
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

static char bus_msg[512];
static size_t bus_len;

/* A mapped program file was cut short under us: reading a page past its
 * new end faults with BUS_ADRERR. Nothing of the run can be trusted. */
static void on_bus(int sig, siginfo_t *si, void *uc)
{
    (void)uc;
    if (si->si_code == BUS_ADRERR) {
        ncp_outfile_discard_all_now();
        (void)!write(2, bus_msg, bus_len);
        _exit(2);
    }
    signal(sig, SIG_DFL);   /* anything else: the fault as it is */
}

/* The temporary output files go with the process; then the signal's own
 * end, so that the caller sees what killed us. */
static void on_fatal(int sig)
{
    ncp_outfile_discard_all_now();
    signal(sig, SIG_DFL);
    raise(sig);
}

void ncp_cli_catch_input_faults(const char *prog, int stops_too)
{
    int k = snprintf(bus_msg, sizeof bus_msg,
                     "%s: error: input changed while reading (a program file was cut short)\n",
                     prog);
    bus_len = k > 0 && (size_t)k < sizeof bus_msg ? (size_t)k : 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = on_bus;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGBUS, &sa, NULL);
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGHUP, &sa, NULL);
    sigaction(SIGPIPE, &sa, NULL);
    if (stops_too) {
        sigaction(SIGINT, &sa, NULL);
        sigaction(SIGTERM, &sa, NULL);
    }
}
