/* The loaded program's text as the NCK checked it and runs it: not the
 * file, which may have been written over since (the panel shows this). */
#include "control.h"

int ncp_nck_program_text(const struct ncp_nck *n, const char **text, size_t *len)
{
    if (!n->have_prog)
        return -1;
    *text = n->prog.text;
    *len = n->prog.len;
    return 0;
}
