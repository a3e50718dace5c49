/* The parameter file and the tool table, kept up to date between jobs
 * (persist.h). A change is written once the job that made it has ended,
 * and the commands that change or depend on it wait for the write
 * (control.c): whatever was accepted is on the disk before the next such
 * command runs, so a kill -9 after that loses nothing, and the file is
 * never torn. */
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
        if (!(p->tools_base = ncp_analyzer_new(NULL, d)) ||
            !(p->tools_sent = ncp_analyzer_new(NULL, d)))
            return -1;
        ncp_analyzer_copy_tools(p->tools_base, interp);
        ncp_analyzer_copy_tools(p->tools_sent, interp);
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
    ncp_analyzer_free(p->tools_sent);
    p->tools_base = p->tools_sent = NULL;
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

int nck_persist_changes(struct nck_persist *p, const struct ncp_analyzer *interp, int again)
{
    int changed = 0;
    if (p->vf) {
        for (int k = 1; k < NCP_VAR_PARAMS; k++) {
            if (!p->vf->listed[k])
                continue;
            double v = ncp_analyzer_param(interp, k);
            if (v != p->vf->value[k])
                changed |= NCK_PERSIST_VARS;
            p->vf->value[k] = v;
        }
        changed |= again & NCK_PERSIST_VARS;
    }
    if (p->tool_path) {
        if (!ncp_analyzer_same_tools(interp, p->tools_sent)) {
            ncp_analyzer_copy_tools(p->tools_sent, interp);
            changed |= NCK_PERSIST_TOOLS;
        }
        changed |= again & NCK_PERSIST_TOOLS;
    }
    return changed;
}

int nck_persist_write_vars(const char *path, const struct ncp_var_file *vf, char *why,
                           size_t len)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (ncp_var_file_write(path, vf, &d) != NCP_OK)
        return snprintf(why, len, "%s", d.msg), -1;
    return 1;
}

int nck_persist_write_tools(const char *path, const struct ncp_analyzer *tools,
                            struct ncp_analyzer *base, char *why, size_t len)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int w = 0;
    if (ncp_analyzer_save_tool_table(tools, base, path, &w, &d) != NCP_OK)
        return snprintf(why, len, "%s", d.msg), -1;
    if (w)
        ncp_analyzer_copy_tools(base, tools);
    return w;
}
