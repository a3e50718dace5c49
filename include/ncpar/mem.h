/* Working memory of the stage threads: rings, buffers and the program text.
 *
 * Prefaulted before the threads start, so that none of them stops for a
 * first-touch page fault, and, from 512 KB up, on 2 MB pages where the kernel
 * offers transparent huge pages for advised memory. Under this host's shadow
 * paging every 4 KB page costs microseconds to fault in and again to unmap: a
 * 1 MB buffer with MAP_POPULATE took 0.57 ms to map, touch and unmap (median of
 * 200), the same on one 2 MB page 0.065 ms; a run of the pipeline has three
 * such buffers (bench/RESULTS.md, "Program text and buffers on huge pages"). */
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

/* `bytes` (> 0) of zeroed memory, every page of it in. 0, or -1 (no memory). */
int ncp_mem_map(struct ncp_mem *m, size_t bytes);
/* `bytes` (> 0) of zeroed memory left to fault in on first touch (a read()
 * into it is the first touch: the kernel fills each 2 MB page in one go). */
int ncp_mem_reserve(struct ncp_mem *m, size_t bytes);
/* Give it back (nothing for a cleared m); m is cleared. */
void ncp_mem_unmap(struct ncp_mem *m);
/* 1 if transparent huge pages are enabled for advised memory ("[always]" or
 * "[madvise]"): only then is a copy onto anonymous memory cheap here. */
int ncp_mem_huge_usable(void);

#endif
