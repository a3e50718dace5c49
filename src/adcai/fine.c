/* Fine interpolation: a rough record's increments spread evenly over the
 * servo periods of its rough period, then moving averages one rough period
 * long. Spread alone would step the velocity at every rough boundary (an
 * acceleration ratio times what the ACC/DEC kept); the average turns each
 * step into a ramp across the next rough period, the same acceleration the
 * rough stream had. A second average does the same for the S-curve's jerk. */
#include "ncpar/adcai.h"
#include "ma.h"

#include <stdlib.h>

struct ncp_adcai_fine {
    int ratio, windows, k;
    int quiet;                      /* servo periods since a non-zero spread */
    int32_t rough[NCP_AXES];        /* the record being spread */
    int64_t in[NCP_AXES], out[NCP_AXES];
    struct adcai_ma ma[NCP_AXES][2];
    int64_t mem[];
};

struct ncp_adcai_fine *ncp_adcai_fine_new(int ratio, int windows)
{
    if (ratio < 1 || ratio > NCP_ADCAI_WINDOW_MAX || windows < 1 || windows > 2)
        return NULL;
    size_t words = (size_t)NCP_AXES * 2 * (size_t)ratio;
    struct ncp_adcai_fine *f = malloc(sizeof *f + words * sizeof f->mem[0]);
    if (!f)
        return NULL;
    f->ratio = ratio;
    f->windows = windows;
    int64_t *m = f->mem;
    for (int j = 0; j < NCP_AXES; j++)
        for (int w = 0; w < 2; w++) {
            f->ma[j][w] = (struct adcai_ma){ .n = ratio, .win = m };
            m += ratio;
        }
    ncp_adcai_fine_reset(f);
    return f;
}

void ncp_adcai_fine_free(struct ncp_adcai_fine *f)
{
    free(f);
}

void ncp_adcai_fine_reset(struct ncp_adcai_fine *f)
{
    for (int j = 0; j < NCP_AXES; j++) {
        f->rough[j] = 0;
        f->in[j] = f->out[j] = 0;
        adcai_ma_reset(&f->ma[j][0], 0);
        adcai_ma_reset(&f->ma[j][1], 0);
    }
    f->k = f->ratio;
    f->quiet = f->windows * f->ratio;
}

void ncp_adcai_fine_load(struct ncp_adcai_fine *f, const int32_t inc[NCP_AXES])
{
    for (int j = 0; j < NCP_AXES; j++)
        f->rough[j] = inc[j];
    f->k = 0;
}

void ncp_adcai_fine_step(struct ncp_adcai_fine *f, int32_t out[NCP_AXES])
{
    /* past the record's last servo period (a caller that did not load): rest */
    int k = f->k < f->ratio ? f->k++ : -1;
    int moved = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        int64_t d = k < 0 ? 0
                          : adcai_floor_div((int64_t)f->rough[j] * (k + 1), f->ratio) -
                                adcai_floor_div((int64_t)f->rough[j] * k, f->ratio);
        moved |= d != 0;
        f->in[j] += d;
        int64_t p = adcai_ma_step(&f->ma[j][0], f->in[j]);
        if (f->windows > 1)
            p = adcai_ma_step(&f->ma[j][1], p);
        out[j] = (int32_t)(p - f->out[j]);
        f->out[j] = p;
    }
    if (moved)
        f->quiet = 0;
    else if (f->quiet < f->windows * f->ratio)
        f->quiet++;
}

int ncp_adcai_fine_drained(const struct ncp_adcai_fine *f)
{
    return f->quiet >= f->windows * (f->ratio - 1) && f->k >= f->ratio;
}
