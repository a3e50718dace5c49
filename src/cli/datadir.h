/* Where cnc-run finds the files it ships with (the panel's, the sample
 * programs, the example machine INIs) without knowing the source tree. */
#ifndef NCPAR_CLI_DATADIR_H
#define NCPAR_CLI_DATADIR_H

#include <stddef.h>

/* The folder `what` (e.g. "web") beside the executable exe, as the build
 * tree has it (build/web beside build/cnc-run), else in ../share/ncpar/ of
 * the executable's folder, as `make install` and the package place it
 * (PREFIX/bin/cnc-run, PREFIX/share/ncpar/web). Relative to the executable,
 * not a prefix fixed at build time, so a staged install (DESTDIR) or a moved
 * prefix finds its own files. Writes the first that holds `probe` (a file in
 * it) to out, else the installed place; 0, or -1 if out is too small. */
int ncp_cli_data_dir(const char *exe, const char *what, const char *probe, char *out,
                     size_t len);

#endif
