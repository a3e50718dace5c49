/* The window of a mapped program that the process holds (ncpar/feeder.h). */
#include "ncpar/feeder.h"

#include <sys/mman.h>
#include <unistd.h>

void ncp_source_window_start(struct ncp_source_window *w, const struct ncp_source *src,
                             uint64_t lag)
{
    w->text = src->mapped ? src->text : NULL;
    w->end = src->len;
    w->next = src->mapped ? 0 : UINT64_MAX;
    w->dropped = 0;
    w->lag = lag;
}

void ncp_source_window_move(struct ncp_source_window *w, uint64_t off)
{
    if (!w->text) {
        w->next = UINT64_MAX;
        return;
    }
    uint64_t page = (uint64_t)sysconf(_SC_PAGESIZE);
    /* the mapping starts on a page: whole pages of it, from offset 0 */
    uint64_t keep = off > w->lag ? (off - w->lag) / page * page : 0;
    if (keep > w->dropped) {
        (void)madvise((void *)(w->text + w->dropped), keep - w->dropped,
                      MADV_DONTNEED);
        w->dropped = keep;
    }
    /* this step and the next: a cold file is read before the reader gets there */
    uint64_t from = off / page * page;
    if (from < w->end) {
        uint64_t len = w->end - from < 2 * NCP_SOURCE_WINDOW_STEP ? w->end - from
                                                                    : 2 * NCP_SOURCE_WINDOW_STEP;
        (void)madvise((void *)(w->text + from), len, MADV_WILLNEED);
    }
    w->next = off + NCP_SOURCE_WINDOW_STEP;
}
