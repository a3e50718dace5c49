/* Working memory of the stage threads: rings, buffers and the program text.
 *
 * Rings and buffers are prefaulted before the threads start, so that none of
 * them stops for a first-touch page fault (microseconds each under this
 * host's shadow paging). The program text is read onto 2 MB pages where the
 * kernel offers transparent huge pages for advised memory: 14 faults instead
 * of 7,000 for a 28 MB program (feeder/text_mem.h). Buffers stay on 4 KB
 * pages: a 1 MB buffer on one 2 MB page took 0.065 ms instead of 0.57 ms to
 * map, touch and unmap (median of 200), but here a fresh 2 MB page now and
 * then costs ~5 ms (the host backs it again after the guest gave it back),
 * and with three such buffers a run of the pipeline paid ~10 ms at its start
 * in 3 runs of 10: more than the saving (bench/RESULTS.md, "Program text on
 * huge pages"). */
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
