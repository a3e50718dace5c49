/* The INI of a service with several NC channels: [CHANNEL_n] sections,
 * each naming the machine INI of channel n (CONFIG = machine.ini, relative
 * to the file's folder). */
#ifndef NCPAR_CLI_CELL_H
#define NCPAR_CLI_CELL_H

#include <limits.h>

#define NCP_CLI_CELL_MAX 16

struct ncp_cli_cell {
    int n;
    int num[NCP_CLI_CELL_MAX];              /* ascending */
    char config[NCP_CLI_CELL_MAX][PATH_MAX];
};

/* 1 when path is a channels INI (read into cell), 0 when it has no
 * [CHANNEL_n] section (a machine INI: cell->n is 0), -1 after printing
 * PATH:LINE: error: ... (a bad channels INI, or one that cannot be read). */
int ncp_cli_cell_load(const char *path, struct ncp_cli_cell *cell);

#endif
