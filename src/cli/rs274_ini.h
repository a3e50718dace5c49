/* LinuxCNC's [RS274NGC] section as `rs274 -i INI` reads it, for `cnc-run
 * parse|check --ini` and for the machine INI of `cnc-run run|serve`:
 * SUBROUTINE_PATH and the REMAP lines. The other sections are the
 * machine's and not read here. */
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
    int oword_nargs;               /* [RS274NGC]OWORD_NARGS (default off) */
    double orient_offset;          /* [RS274NGC]ORIENT_OFFSET (default 0) */
    int no_fanuc_subs;             /* [RS274NGC]DISABLE_FANUC_STYLE_SUB (default off) */
    char *text;                    /* the file: the REMAP texts point into it */
};

/* Reads path's [RS274NGC]; a key it cannot honour is refused naming
 * PATH:LINE on stderr. Returns 0, or -1 (the usage error of exit 1). */
int rs274_ini_load(const char *path, struct rs274_ini *ini);
/* The same section of run's and serve's machine INI, which
 * ncp_machine_cfg_load took already: its other sections are the machine's. */
int rs274_ini_load_machine(const char *path, struct rs274_ini *ini);
void rs274_ini_free(struct rs274_ini *ini);

/* "a:b" of the command line's --subroutine-path and the INI's, in that
 * order (rs274 looks in the current folder first, then those); malloc'd,
 * or NULL when both are NULL. */
char *rs274_ini_join_paths(const char *cli, const char *ini);

/* ini's keys into acfg: the REMAP lines, the INI's keys for
 * #<_ini[...]>, and SUBROUTINE_PATH after acfg's own folders (joined in
 * *joined, the caller's to free). 0, or -1 out of memory (said). */
int rs274_ini_apply(const struct rs274_ini *ini, struct ncp_analyzer_cfg *acfg, char **joined);

/* run and serve: the interpreter of the machine INI at path (NULL: none),
 * whose user M codes are in user_m_dirs (the machine's [RS274NGC]
 * USER_M_PATH, "" none). Reads its [RS274NGC] into ini and acfg, then
 * makes an interpreter of acfg once, so that a REMAP it refuses is said
 * (INI:LINE) before anything moves. 0, or -1 after the message. */
int rs274_ini_machine(const char *path, const char *user_m_dirs, struct rs274_ini *ini,
                      struct ncp_analyzer_cfg *acfg, char **joined);

#endif
