/* cnc-run run --channel: several NC channels in one process. */
#ifndef NCPAR_CLI_CHANNELS_H
#define NCPAR_CLI_CHANNELS_H

#include "ncpar/analyzer.h"
#include "ncpar/pipeline.h"

#include <signal.h>
#include <stdint.h>

/* LCM's channel field and cnc-ctl --channel share this range. */
#define NCP_CLI_CHANNELS_MAX 16

/* What the options outside --channel say, the same for every channel. */
struct ncp_cli_channel_common {
    int virtual_clock;
    double for_s, feed_override;
    enum ncp_thread_mode mode;
    const char *trace;           /* a name pattern (see ncp_cli_channel_trace_name) */
    struct ncp_analyzer_cfg interp;
    const char *backend, *inject, *seed;
    atomic_int *interrupt; /* a stop signal: every channel stops */
    int trace_rings;             /* --trace-rings */
};

/* specs[i] is "N:PROG" or "N:PROG:INI". Runs every channel to its end, each
 * in its own NCK, and reports each; returns the worst exit status. */
int ncp_cli_run_channels(const char *const *specs, int n, const struct ncp_cli_channel_common *c);

/* The trace file of channel num: every "{channel}" in pattern becomes num;
 * without one, ".chNUM" goes before the file name's extension (or at its
 * end). 0, or -1 when it does not fit in len. */
int ncp_cli_channel_trace_name(const char *pattern, int num, char *buf, size_t len);

#endif
