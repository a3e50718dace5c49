/* The command line's timing faults: what a user tries on a machine without
 * editing its INI. */
#include "inject_opts.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ncp_cli_apply_inject(const char *who, const char *spec, const char *seed,
                         struct ncp_machine_cfg *cfg)
{
    struct ncp_inject_cfg *c = &cfg->inject;
    char why[400];
    if (spec) {
        struct ncp_inject_cfg fresh = *c;
        uint64_t keep_seed = fresh.seed;
        int policy = fresh.policy, maxc = fresh.max_consecutive, win = fresh.window;
        int per_axis = fresh.per_axis;
        double maxr = fresh.max_ratio;
        ncp_inject_cfg_default(&fresh);
        fresh.seed = keep_seed;
        fresh.policy = policy;
        fresh.max_consecutive = maxc;
        fresh.max_ratio = maxr;
        fresh.window = win;
        fresh.per_axis = per_axis;
        if (ncp_inject_parse(&fresh, spec, why, sizeof why))
            return fprintf(stderr, "%s: --inject: %s\n", who, why), -1;
        *c = fresh;
    }
    if (seed) {
        char *end;
        errno = 0;
        unsigned long long v = strtoull(seed, &end, 10);
        if (errno || end == seed || *end || seed[0] == '-')
            return fprintf(stderr, "%s: --seed wants a whole number, not '%s'\n", who, seed), -1;
        c->seed = v;
    }
    if (ncp_inject_check(c, cfg->servo_period, why, sizeof why))
        return fprintf(stderr, "%s: --inject: %s\n", who, why), -1;
    return 0;
}
