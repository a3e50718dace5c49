/* ACC/DEC after interpolation: each axis's increments through one moving
 * average (PROFILE = trapezoid) or two in series (scurve). A step in the
 * input velocity comes out as a ramp over the first window; the second turns
 * that ramp's corners into ramps of acceleration, which bounds the jerk. */
#include "ncpar/adcai.h"
#include "ma.h"

#include <stdlib.h>

struct ncp_adcai_accdec {
    int n1, n2;
    int quiet;                      /* periods since the last non-zero input */
    int64_t in[NCP_AXES];           /* input position, relative to the reset */
    int64_t out[NCP_AXES];          /* output position, same origin */
    struct adcai_ma ma[NCP_AXES][2];
    int64_t mem[];                  /* NCP_AXES * (n1 + n2) positions */
};

struct ncp_adcai_accdec *ncp_adcai_accdec_new(int n1, int n2)
{
    if (n1 < 1 || n2 < 1 || n1 > NCP_ADCAI_WINDOW_MAX || n2 > NCP_ADCAI_WINDOW_MAX)
        return NULL;
    size_t words = (size_t)NCP_AXES * (size_t)(n1 + n2);
    struct ncp_adcai_accdec *f = malloc(sizeof *f + words * sizeof f->mem[0]);
    if (!f)
        return NULL;
    f->n1 = n1;
    f->n2 = n2;
    int64_t *m = f->mem;
    for (int j = 0; j < NCP_AXES; j++) {
        f->ma[j][0] = (struct adcai_ma){ .n = n1, .win = m };
        m += n1;
        f->ma[j][1] = (struct adcai_ma){ .n = n2, .win = m };
        m += n2;
    }
    ncp_adcai_accdec_reset(f);
    return f;
}

void ncp_adcai_accdec_free(struct ncp_adcai_accdec *f)
{
    free(f);
}

void ncp_adcai_accdec_reset(struct ncp_adcai_accdec *f)
{
    for (int j = 0; j < NCP_AXES; j++) {
        f->in[j] = f->out[j] = 0;
        adcai_ma_reset(&f->ma[j][0], 0);
        adcai_ma_reset(&f->ma[j][1], 0);
    }
    f->quiet = f->n1 + f->n2;
}

void ncp_adcai_accdec_step(struct ncp_adcai_accdec *f, const int32_t in[NCP_AXES],
                           int32_t out[NCP_AXES])
{
    int moved = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        moved |= in[j] != 0;
        f->in[j] += in[j];
        int64_t p = adcai_ma_step(&f->ma[j][0], f->in[j]);
        p = adcai_ma_step(&f->ma[j][1], p);
        /* the average of positions within one rough period's motion of each
         * other: the difference fits the input's int32 */
        out[j] = (int32_t)(p - f->out[j]);
        f->out[j] = p;
    }
    if (moved)
        f->quiet = 0;
    else if (f->quiet < f->n1 + f->n2)
        f->quiet++;
}

/* The first window holds only the last input position n1 - 1 periods after
 * it arrived, the second n2 - 1 periods after that. */
int ncp_adcai_accdec_drained(const struct ncp_adcai_accdec *f)
{
    return f->quiet >= f->n1 + f->n2 - 2;
}
