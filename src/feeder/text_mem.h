/* Program text copied into anonymous memory on transparent huge pages
 * (module-internal header).
 *
 * A mapped file costs its first reader a fault per 4 KB page; under this
 * host's shadow paging that is ~1.5 us a page even after MAP_POPULATE, 11 ms
 * for a 28 MB program, and 2 ms more to unmap it at exit. read() into a region
 * on 2 MB pages (ncpar/mem.h) costs 6 ms for the same file (the copy and 14
 * zeroed 2 MB pages), then nothing to touch (0.25 ms) or to unmap (0.3 ms)
 * (bench/RESULTS.md, "Program text on huge pages"). The same read
 * into small anonymous pages took 100 ms here: a copy is only made where the
 * kernel offers huge pages (ncp_mem_huge_usable). */
#ifndef NCP_FEEDER_TEXT_MEM_H
#define NCP_FEEDER_TEXT_MEM_H

#include <stddef.h>

#include "ncpar/mem.h"

struct ncp_text_mem {
    char *text;
    size_t len;       /* bytes of text read */
    size_t cap;       /* room at text */
    struct ncp_mem mem;
};

/* The first `size` (> 0) bytes of regular file fd (fewer if it is shorter
 * now). 0, or -1 with errno set and nothing held. */
int ncp_text_mem_read_file(struct ncp_text_mem *m, int fd, size_t size);
/* Everything fd gives until its end (a pipe). 0, or -1 with errno set. */
int ncp_text_mem_read_stream(struct ncp_text_mem *m, int fd);
void ncp_text_mem_free(struct ncp_text_mem *m);

#endif
