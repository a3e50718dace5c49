/* A moving average over positions in integer units, shared by the ACC/DEC
 * and the fine interpolator. Averaging positions, not increments, with one
 * floor division per period makes it exact: once n equal positions fill the
 * window the output is that position, so the increments out sum to the
 * increments in, whatever was rounded on the way. Private to src/adcai. */
#ifndef NCPAR_ADCAI_MA_H
#define NCPAR_ADCAI_MA_H

#include <stdint.h>
#include <string.h>

struct adcai_ma {
    int n, head;
    int64_t sum;        /* of the n positions in the window */
    int64_t *win;       /* n positions, the caller's memory */
};

static inline int64_t adcai_floor_div(int64_t a, int64_t n)
{
    int64_t q = a / n;
    return (a % n < 0) ? q - 1 : q;
}

/* At rest at pos. */
static inline void adcai_ma_reset(struct adcai_ma *m, int64_t pos)
{
    for (int i = 0; i < m->n; i++)
        m->win[i] = pos;
    m->sum = pos * m->n;
    m->head = 0;
}

/* The next input position in, the averaged position out. */
static inline int64_t adcai_ma_step(struct adcai_ma *m, int64_t pos)
{
    m->sum += pos - m->win[m->head];
    m->win[m->head] = pos;
    if (++m->head == m->n)
        m->head = 0;
    return adcai_floor_div(m->sum, m->n);
}

#endif
