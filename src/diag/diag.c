#include "ncpar/diag.h"

#include <stdarg.h>
#include <stdio.h>

int ncp_diag_set(struct ncp_diag *d, enum ncp_status code, uint32_t line,
                 uint16_t col, const char *fmt, ...)
{
    va_list ap;
    d->code = (uint16_t)code;
    d->line = line;
    d->col = col;
    va_start(ap, fmt);
    /* the analyzer loses va_start across the line above */
    vsnprintf(d->msg, sizeof d->msg, fmt, ap); // NOLINT(clang-analyzer-valist.Uninitialized)
    va_end(ap);
    return (int)code;
}
