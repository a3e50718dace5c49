/* Program text copied into anonymous memory on transparent huge pages
 * (module-internal header).
 *
 * A mapped file costs its first reader a fault per 4 KB page (under a
 * hypervisor's shadow paging even after MAP_POPULATE), and more to unmap it
 * at exit. read() into a region on 2 MB pages (ncpar/mem.h) pays the copy
 * and a few zeroed huge pages once, then nothing to touch or to unmap
 * (bench/RESULTS.md, "Program text on huge pages"). The same read into small
 * anonymous pages costs far more than the mapping: a copy is only made where
 * the kernel offers huge pages (ncp_mem_huge_usable). */
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
/* What a stream reader is told after each read(): the text so far. It
 * returns 0 to read on, or the length of text to keep when the rest is not
 * wanted (the program has ended in it). */
typedef size_t (*ncp_text_stop_fn)(void *ctx, const char *text, size_t len);

/* What fd gives until its end (a pipe), until `stop` (may be NULL) has seen
 * the program's end, or until more than `max` bytes came (then -1 with errno
 * EFBIG and nothing held). 0, or -1 with errno set. */
int ncp_text_mem_read_stream(struct ncp_text_mem *m, int fd, size_t max,
                             ncp_text_stop_fn stop, void *ctx);
void ncp_text_mem_free(struct ncp_text_mem *m);

#endif
