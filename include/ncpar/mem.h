/* Working memory of the stage threads: rings, buffers and the program text.
 *
 * Rings and buffers are prefaulted before the threads start, so that none of
 * them stops for a first-touch page fault (microseconds each under a
 * hypervisor's shadow paging). The program text is read onto 2 MB pages where
 * the kernel offers transparent huge pages for advised memory: one fault per
 * 2 MB instead of one per 4 KB (feeder/text_mem.h). Buffers stay on 4 KB
 * pages: a huge page is cheaper to map and touch, but in a virtual machine a
 * fresh 2 MB page now and then costs milliseconds (the host backs it again
 * after the guest gave it back), more than the saving for buffers of a
 * megabyte or two (bench/RESULTS.md, "Program text on huge pages"). */
#ifndef NCPAR_MEM_H
#define NCPAR_MEM_H

#include <stddef.h>

struct ncp_mem {
    void *p;          /* the memory: 4 KB aligned, 2 MB when on huge pages */
    size_t bytes;     /* usable at p (at least what was asked for) */
    void *base;       /* the mapping itself, for the unmap */
    size_t base_len;
    int huge;         /* advised onto 2 MB pages */
};

/* `bytes` (> 0) of zeroed memory on 4 KB pages, every page of it in.
 * 0, or -1 (no memory). */
int ncp_mem_map(struct ncp_mem *m, size_t bytes);
/* `bytes` (> 0) of zeroed memory left to fault in on first touch, on 2 MB
 * pages from 512 KB up where they are offered (a read() into it is the first
 * touch: the kernel fills each 2 MB page in one go). */
int ncp_mem_reserve_huge(struct ncp_mem *m, size_t bytes);
/* Give it back (nothing for a cleared m); m is cleared. */
void ncp_mem_unmap(struct ncp_mem *m);
/* 1 if transparent huge pages are enabled for advised memory ("[always]" or
 * "[madvise]"): only then is a copy onto anonymous memory cheap here. */
int ncp_mem_huge_usable(void);

#endif
