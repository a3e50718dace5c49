/* --inject SPEC[,SPEC...] and --seed N of run and serve, over the INI's [INJECT]. */
#ifndef NCPAR_CLI_INJECT_OPTS_H
#define NCPAR_CLI_INJECT_OPTS_H

#include "ncpar/config.h"

/* spec and seed as given (NULL: not given). --inject replaces the INI's
 * specs (its policy and miss limits stay); --seed its SEED. Prints
 * "WHO: --inject: bad spec ..." and returns -1 on an error (exit 1). */
int ncp_cli_apply_inject(const char *who, const char *spec, const char *seed,
                         struct ncp_machine_cfg *cfg);

#endif
