/* Lock-free single-producer/single-consumer ring. Each index is written by one
 * side only; release/acquire on it publishes the slot's bytes. */
#include "ncpar/rt.h"

#include <stdlib.h>
#include <string.h>

int ncp_spsc_init(struct ncp_spsc *r, size_t elem_size, size_t capacity)
{
    size_t cap = 2;
    while (cap < capacity)
        cap <<= 1;
    atomic_init(&r->head, 0);
    atomic_init(&r->tail, 0);
    r->mask = cap - 1;
    r->elem = elem_size;
    r->buf = calloc(cap, elem_size);
    if (!r->buf)
        return -1;
    /* calloc may hand out untouched zero pages: fault them in now */
    memset(r->buf, 0, cap * elem_size);
    return 0;
}

void ncp_spsc_destroy(struct ncp_spsc *r)
{
    free(r->buf);
    r->buf = NULL;
}

int ncp_spsc_push(struct ncp_spsc *r, const void *item)
{
    size_t t = atomic_load_explicit(&r->tail, memory_order_relaxed);
    size_t h = atomic_load_explicit(&r->head, memory_order_acquire);
    if (t - h > r->mask)
        return -1;
    memcpy(r->buf + (t & r->mask) * r->elem, item, r->elem);
    atomic_store_explicit(&r->tail, t + 1, memory_order_release);
    return 0;
}

int ncp_spsc_pop(struct ncp_spsc *r, void *item)
{
    size_t h = atomic_load_explicit(&r->head, memory_order_relaxed);
    size_t t = atomic_load_explicit(&r->tail, memory_order_acquire);
    if (h == t)
        return -1;
    memcpy(item, r->buf + (h & r->mask) * r->elem, r->elem);
    atomic_store_explicit(&r->head, h + 1, memory_order_release);
    return 0;
}

size_t ncp_spsc_count(struct ncp_spsc *r)
{
    size_t t = atomic_load_explicit(&r->tail, memory_order_acquire);
    size_t h = atomic_load_explicit(&r->head, memory_order_acquire);
    return t - h;
}

size_t ncp_spsc_capacity(const struct ncp_spsc *r)
{
    return r->mask + 1;
}
