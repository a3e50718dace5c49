/* What the operator set that outlives the service (persist.c): the
 * interpreter's persistent parameters in LinuxCNC's parameter file and the
 * tool offsets in the tool table. The service thread takes what changed
 * between jobs (the interpreter is idle then), reading memory only; the
 * NCK's disk writer (diskwriter.h) writes it: writing blocks on the disk,
 * which neither the service thread nor the real-time path may wait for. */
#ifndef NCPAR_NCK_PERSIST_H
#define NCPAR_NCK_PERSIST_H

#include "ncpar/analyzer.h"

#include <stddef.h>

struct nck_persist {
    struct ncp_var_file *vf;        /* as last handed to the writer; NULL: no parameter file */
    char var_path[512];
    const char *tool_path;          /* the tool table, or NULL */
    /* the table's entries as last handed to the writer (the service
     * thread's), and as last loaded or written (the writer's, against which
     * it writes only the tools this NCK changed) */
    struct ncp_analyzer *tools_sent, *tools_base;
};

enum { NCK_PERSIST_VARS = 1, NCK_PERSIST_TOOLS = 2 };

/* Takes the file's values into the interpreter, and keeps the tool table
 * as loaded. 0, or -1 with d->msg. */
int nck_persist_init(struct nck_persist *p, const struct ncp_var_file *vars,
                     const char *var_path, const char *tool_path, struct ncp_analyzer *interp,
                     struct ncp_diag *d);
void nck_persist_free(struct nck_persist *p);

/* The lines that make the interpreter take the file's frames, as rs274's
 * start-up does (G92 when #5210 says it was applied, then the coordinate
 * system of #5220); "" without a parameter file. */
void nck_persist_restore_text(const struct nck_persist *p, char *buf, size_t len);

/* What the interpreter changed since it was last handed over, now in p->vf
 * and p->tools_sent: a bit per file (NCK_PERSIST_VARS, NCK_PERSIST_TOOLS).
 * The bits of again are taken as changed whatever the interpreter holds (a
 * write of them failed). Reads memory only. */
int nck_persist_changes(struct nck_persist *p, const struct ncp_analyzer *interp, int again);

/* The writer's: the parameter file with vf's values; the tool table with
 * tools' entries where they differ from base, then base becomes them. 1
 * written, 0 nothing to write, or -1 with why[] (nothing is taken as
 * written). Block on the disk. */
int nck_persist_write_vars(const char *path, const struct ncp_var_file *vf, char *why,
                           size_t len);
int nck_persist_write_tools(const char *path, const struct ncp_analyzer *tools,
                            struct ncp_analyzer *base, char *why, size_t len);

#endif
