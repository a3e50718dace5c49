/* The NCK's events, oldest first, for the service to publish. A full queue
 * drops the oldest: an operator needs the latest word more than the first. */
#include "control.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void nck_post(struct nck_core *n, int kind, const char *file, uint32_t line, uint32_t col,
              const char *fmt, ...)
{
    pthread_mutex_lock(&n->cross.ev_lock);
    if (n->cross.ev_count == NCK_EVENTS) {
        n->cross.ev_head = (n->cross.ev_head + 1) % NCK_EVENTS;
        n->cross.ev_count--;
        n->cross.ev_dropped++;
    }
    struct ncp_nck_event *e = &n->cross.ev[(n->cross.ev_head + n->cross.ev_count) % NCK_EVENTS];
    n->cross.ev_count++;
    e->kind = kind;
    snprintf(e->file, sizeof e->file, "%s", file ? file : "");
    e->line = line;
    e->col = col;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->text, sizeof e->text, fmt, ap);
    va_end(ap);
    pthread_mutex_unlock(&n->cross.ev_lock);
}

int ncp_nck_next_event(struct ncp_nck *s, struct ncp_nck_event *ev)
{
    struct nck_core *n = &s->core;
    pthread_mutex_lock(&n->cross.ev_lock);
    if (n->cross.ev_dropped) {
        /* the reader learns that it missed some, rather than nothing */
        memset(ev, 0, sizeof *ev);
        ev->kind = NCP_EV_INFO;
        snprintf(ev->text, sizeof ev->text, "%llu older events dropped (the NCK keeps %d)",
                 (unsigned long long)n->cross.ev_dropped, NCK_EVENTS);
        n->cross.ev_dropped = 0;
        pthread_mutex_unlock(&n->cross.ev_lock);
        return 1;
    }
    int got = n->cross.ev_count > 0;
    if (got) {
        *ev = n->cross.ev[n->cross.ev_head];
        n->cross.ev_head = (n->cross.ev_head + 1) % NCK_EVENTS;
        n->cross.ev_count--;
    }
    pthread_mutex_unlock(&n->cross.ev_lock);
    return got;
}
