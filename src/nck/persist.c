/* The parameter file and the tool table, kept up to date between jobs
 * (persist.h). A change is written once the job that made it has ended:
 * whatever was accepted is on the disk before the next command runs, so a
 * kill -9 after that loses nothing, and the file is never torn. */
#include "persist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int nck_persist_init(struct nck_persist *p, const struct ncp_var_file *vars,
                     const char *var_path, const char *tool_path, struct ncp_analyzer *interp,
                     struct ncp_diag *d)
{
    memset(p, 0, sizeof *p);
    p->tool_path = tool_path;
    if (tool_path) {
        /* the interpreter's table is taken below: no second read */
        if (!(p->tools_base = ncp_analyzer_new(NULL, d)))
            return -1;
        ncp_analyzer_copy_tools(p->tools_base, interp);
    }
    if (!vars)
        return 0;
    if (!(p->vf = malloc(sizeof *p->vf)))
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory"), -1;
    *p->vf = *vars;
    snprintf(p->var_path, sizeof p->var_path, "%s", var_path);
    for (int k = 1; k < NCP_VAR_PARAMS; k++)
        if (vars->listed[k])
            ncp_analyzer_set_param(interp, k, vars->value[k]);
    return 0;
}

void nck_persist_free(struct nck_persist *p)
{
    free(p->vf);
    p->vf = NULL;
    ncp_analyzer_free(p->tools_base);
    p->tools_base = NULL;
}

void nck_persist_restore_text(const struct nck_persist *p, char *buf, size_t len)
{
    static const char *const sys[] = { "G54", "G55", "G56", "G57", "G58",
                                       "G59", "G59.1", "G59.2", "G59.3" };
    if (!p->vf) {
        snprintf(buf, len, "%s", "");
        return;
    }
    int k = (int)p->vf->value[5220];   /* 1..9, checked when read */
    if (k < 1 || k > 9)
        k = 1;
    /* selecting a system loads its offsets from the parameters; the one
     * selected already (G54 at start) would only be "continued" */
    snprintf(buf, len, "%s%s\n%s\n", p->vf->value[5210] != 0 ? "G92.3\n" : "",
             k == 1 ? "G55" : "G54", sys[k - 1]);
}

int nck_persist_save(struct nck_persist *p, const struct ncp_analyzer *interp, char *why,
                     size_t len)
{
    int written = 0;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (p->vf) {
        int changed = 0;
        for (int k = 1; k < NCP_VAR_PARAMS; k++) {
            if (!p->vf->listed[k])
                continue;
            double v = ncp_analyzer_param(interp, k);
            changed |= v != p->vf->value[k];
            p->vf->value[k] = v;
        }
        if (changed && ncp_var_file_write(p->var_path, p->vf, &d) != NCP_OK) {
            /* the next save tries again: nothing is taken as written */
            p->vf->value[5220] = -1;
            return snprintf(why, len, "%s", d.msg), -1;
        }
        written |= changed;
    }
    if (p->tool_path) {
        int w = 0;
        if (ncp_analyzer_save_tool_table(interp, p->tools_base, p->tool_path, &w, &d) != NCP_OK)
            return snprintf(why, len, "%s", d.msg), -1;
        if (w)
            ncp_analyzer_copy_tools(p->tools_base, interp);
        written |= w ? 2 : 0;
    }
    return written;
}
