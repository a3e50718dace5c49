/* What the operator set that outlives the service (persist.c): the
 * interpreter's persistent parameters in LinuxCNC's parameter file and the
 * tool offsets in the tool table. Runs on the service thread between jobs
 * (the interpreter is idle then), never on the real-time path: writing
 * blocks on the disk. */
#ifndef NCPAR_NCK_PERSIST_H
#define NCPAR_NCK_PERSIST_H

#include "ncpar/analyzer.h"

#include <stddef.h>

struct nck_persist {
    struct ncp_var_file *vf;        /* as last written; NULL: no parameter file */
    char var_path[512];
    const char *tool_path;          /* the tool table, or NULL */
    struct ncp_analyzer *tools_base;/* its entries as last loaded or written */
};

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

/* Writes the files whose contents the interpreter changed. Returns a bit
 * per file written (1 the parameter file, 2 the tool table), or -1 with
 * why[] (what was written before the failure stays written). */
int nck_persist_save(struct nck_persist *p, const struct ncp_analyzer *interp, char *why,
                     size_t len);

#endif
