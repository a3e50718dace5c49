#include "ncpar/diag.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ncp_diag_set(struct ncp_diag *d, enum ncp_status code, uint32_t line,
                 uint16_t col, const char *fmt, ...)
{
    va_list ap;
    d->code = (uint16_t)code;
    d->line = line;
    d->col = col;
    d->file = NULL;
    va_start(ap, fmt);
    /* the analyzer loses va_start across the line above */
    vsnprintf(d->msg, sizeof d->msg, fmt, ap);
    va_end(ap);
    return (int)code;
}

/* Subroutine files are few (one per called name at most): a table that
 * only grows, searched from the start. */
static const char *names[NCP_DIAG_FILE_TAGS];
static unsigned n_names;
static pthread_mutex_t names_lock = PTHREAD_MUTEX_INITIALIZER;

/* Under names_lock: the name's tag, added if new (0 when it cannot be). */
static unsigned tag_locked(const char *name)
{
    for (unsigned k = 0; k < n_names; k++)
        if (strcmp(names[k], name) == 0)
            return k + 1;
    if (n_names == NCP_DIAG_FILE_TAGS)
        return 0;
    size_t len = strlen(name);
    char *copy = malloc(len + 1);
    if (!copy)
        return 0;
    memcpy(copy, name, len + 1);
    names[n_names++] = copy;
    return n_names;
}

unsigned ncp_diag_file_tag(const char *name)
{
    pthread_mutex_lock(&names_lock);
    unsigned tag = tag_locked(name);
    pthread_mutex_unlock(&names_lock);
    return tag;
}

const char *ncp_diag_file_of_tag(unsigned tag)
{
    pthread_mutex_lock(&names_lock);
    const char *name = tag >= 1 && tag <= n_names ? names[tag - 1] : NULL;
    pthread_mutex_unlock(&names_lock);
    return name;
}
