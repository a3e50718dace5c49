/* LinuxCNC's [RS274NGC] section as `rs274 -i INI` reads it, for `cnc-run
 * parse|check --ini`: SUBROUTINE_PATH and the REMAP lines. The other
 * sections are the machine's and not read here. */
#ifndef NCP_CLI_RS274_INI_H
#define NCP_CLI_RS274_INI_H

#include "ncpar/analyzer.h"

struct rs274_ini {
    char *sub_path;                /* SUBROUTINE_PATH, folders made absolute from
                                      the INI's folder; NULL without one */
    struct ncp_remap_line *remaps;
    int n_remaps;
    struct ncp_ini_var *vars;      /* every key, for #<_ini[SECTION]KEY> */
    int n_vars;
    int ini_vars;                  /* [RS274NGC]INI_VARS (default on) */
    char *text;                    /* the file: the REMAP texts point into it */
};

/* Reads path's [RS274NGC]; a key it cannot honour is refused naming
 * PATH:LINE on stderr. Returns 0, or -1 (the usage error of exit 1). */
int rs274_ini_load(const char *path, struct rs274_ini *ini);
void rs274_ini_free(struct rs274_ini *ini);

/* "a:b" of the command line's --subroutine-path and the INI's, in that
 * order (rs274 looks in the current folder first, then those); malloc'd,
 * or NULL when both are NULL. */
char *rs274_ini_join_paths(const char *cli, const char *ini);

#endif
