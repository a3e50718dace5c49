/* The central ADCAI NCK: rough interpolator -> ACC/DEC -> fine interpolator,
 * one servo period per call, behind the planner's protocol so that the NCK's
 * planner thread, position loop, trace and summary take it as they take the
 * ADCBI planner. */
#include "ncpar/adcai.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ncp_adcai {
    struct ncp_machine_cfg cfg;     /* the rough stage reads its limits here */
    struct ncp_adcai_rough *rough;
    struct ncp_adcai_accdec *acc;
    struct ncp_adcai_fine *fine;
    int ratio, k;                   /* servo periods per rough period, and which one */
    int stop_pending;               /* a record with the stop flag went down: drain first */
    int finishing;                  /* no segment follows the queued ones */
    int64_t pos[NCP_AXES];          /* the setpoint, nm */
    struct ncp_adcai_rough_rec tag; /* the newest record's block */
    /* The chain runs one servo period ahead of the setpoints, so that each
     * setpoint's velocity is the one at its point (the mean of the periods
     * either side) and not the one of the period before it: the position
     * loop's S-curve time scaling reads the stream through a curve on those
     * velocities, which a half-period lag would make wobble. */
    int32_t ahead[NCP_AXES];
    struct ncp_adcai_rough_rec ahead_tag;
    int have_ahead, ahead_moves;
    struct ncp_planner_stats st;
    /* the distributed mode's tap: the sums so far, and the ahead sample's */
    void (*tap)(void *ctx, const struct ncp_adcai_tap *t);
    void *tap_ctx;
    struct ncp_adcai_tap sums, ahead_rec;
    int loaded;                     /* produce() loaded a record for its sample */
};

struct ncp_adcai *ncp_adcai_new(const struct ncp_machine_cfg *cfg, const double start[NCP_AXES])
{
    int n[2], ratio = ncp_machine_cfg_ipo_ratio(cfg);
    if (ratio < 1 || ncp_adcai_windows(cfg, cfg->servo_period * ratio, n) != 0)
        return NULL;
    struct ncp_adcai *a = calloc(1, sizeof *a);
    if (!a)
        return NULL;
    a->cfg = *cfg;
    a->ratio = ratio;
    a->rough = ncp_adcai_rough_new(&a->cfg, cfg->servo_period * ratio, start);
    a->acc = ncp_adcai_accdec_new(n[0], n[1]);
    a->fine = ncp_adcai_fine_new(ratio, cfg->profile == NCP_PROFILE_SCURVE ? 2 : 1);
    if (!a->rough || !a->acc || !a->fine) {
        ncp_adcai_free(a);
        return NULL;
    }
    ncp_adcai_reset(a, start);
    return a;
}

void ncp_adcai_free(struct ncp_adcai *a)
{
    if (!a)
        return;
    ncp_adcai_rough_free(a->rough);
    ncp_adcai_accdec_free(a->acc);
    ncp_adcai_fine_free(a->fine);
    free(a);
}

int ncp_adcai_full(const struct ncp_adcai *a)
{
    return ncp_adcai_rough_full(a->rough);
}

size_t ncp_adcai_queued(const struct ncp_adcai *a)
{
    return ncp_adcai_rough_queued(a->rough);
}

static int drained(const struct ncp_adcai *a)
{
    return ncp_adcai_accdec_drained(a->acc) && ncp_adcai_fine_drained(a->fine);
}

int ncp_adcai_idle(const struct ncp_adcai *a)
{
    return !ncp_adcai_rough_busy(a->rough) && drained(a) && !(a->have_ahead && a->ahead_moves);
}

void ncp_adcai_push(struct ncp_adcai *a, const struct ncp_seg *s)
{
    ncp_adcai_rough_push(a->rough, s);
    a->st.segments++;
}

void ncp_adcai_finish(struct ncp_adcai *a)
{
    ncp_adcai_rough_finish(a->rough);
    a->finishing = 1;
}

void ncp_adcai_restart(struct ncp_adcai *a)
{
    ncp_adcai_rough_restart(a->rough);
    a->finishing = 0;
}

void ncp_adcai_reset(struct ncp_adcai *a, const double pos[NCP_AXES])
{
    ncp_adcai_rough_reset(a->rough, pos);
    ncp_adcai_rough_position(a->rough, a->pos);
    ncp_adcai_accdec_reset(a->acc);
    ncp_adcai_fine_reset(a->fine);
    a->k = 0;
    a->have_ahead = 0;
    a->stop_pending = 0;
    a->finishing = 0;
    memset(&a->tag, 0, sizeof a->tag);
    memset(&a->sums, 0, sizeof a->sums);
}

void ncp_adcai_set_tap(struct ncp_adcai *a, void (*fn)(void *ctx, const struct ncp_adcai_tap *t),
                       void *ctx)
{
    a->tap = fn;
    a->tap_ctx = ctx;
}

void ncp_adcai_get_stats(const struct ncp_adcai *a, struct ncp_planner_stats *st)
{
    *st = a->st;
}

/* The setpoint of the position a->pos moved by inc this servo period, with
 * the velocity between inc and next, the period after it. */
static void setpoint(struct ncp_adcai *a, const int32_t inc[NCP_AXES], const int32_t next[NCP_AXES],
                     const struct ncp_adcai_rough_rec *tag, struct ncp_setpoint *out)
{
    double xyz = 0, abc = 0, vxyz = 0, vabc = 0, d[NCP_AXES];
    for (int j = 0; j < NCP_AXES; j++) {
        a->pos[j] += inc[j];
        out->pos[j] = (double)a->pos[j] / NCP_ADCAI_UNITS_PER_MM;
        double step = inc[j] / NCP_ADCAI_UNITS_PER_MM;
        d[j] = 0.5 * (inc[j] + next[j]) / NCP_ADCAI_UNITS_PER_MM;
        if (j < 3) {
            xyz += step * step;
            vxyz += d[j] * d[j];
        } else if (j < 6) {
            abc += step * step;
            vabc += d[j] * d[j];
        }
    }
    /* path length as the planner measures it: X Y Z, else A B C */
    double l = sqrt(xyz > 0 ? xyz : abc), lv = sqrt(vxyz > 0 ? vxyz : vabc);
    for (int j = 0; j < NCP_AXES; j++)
        out->dir[j] = lv > 0 ? d[j] / lv : 0;
    out->v = lv / a->cfg.servo_period;
    a->st.path_length += l;
    out->line = tag->line;
    out->aux = tag->aux;
    out->tool_z = tag->tool_z;
    out->rev_rpm = l > 0 ? tag->rev_rpm : 0;
    out->flags = l > 0 ? tag->motion : 0;
}

/* The next rough record into the ACC/DEC and the fine interpolator: 1, or 0
 * when everything is at rest and there is nothing to interpolate. While a
 * stop drains, the rough stage waits and the filters get zeros. */
static int next_record(struct ncp_adcai *a)
{
    struct ncp_adcai_rough_rec rec;
    memset(&rec, 0, sizeof rec);
    /* a block that came after the one before it had ended, while the
     * filters still move it: the stop its corner needs is taken now */
    if (!a->stop_pending && ncp_adcai_rough_late_stop(a->rough) && !drained(a))
        a->stop_pending = 1;
    if (a->stop_pending && drained(a))
        a->stop_pending = 0;
    /* at rest the setpoint is where the rough stage is: a move that starts
     * elsewhere (the machine was homed or moved meanwhile) moves both */
    if (!a->stop_pending && drained(a) && ncp_adcai_rough_align(a->rough))
        ncp_adcai_rough_position(a->rough, a->pos);
    int got = !a->stop_pending && ncp_adcai_rough_step(a->rough, &rec);
    if (!got && !a->stop_pending && drained(a))
        return 0;
    if (got) {
        a->tag = rec;
        a->stop_pending = rec.stop;
    }
    int32_t acc[NCP_AXES];
    ncp_adcai_accdec_step(a->acc, rec.inc, acc);
    ncp_adcai_fine_load(a->fine, acc);
    for (int j = 0; j < NCP_AXES; j++) {
        /* wraps after 2.1 m of travel summed: the LLCs take differences */
        a->sums.rough[j] = (int32_t)((uint32_t)a->sums.rough[j] + (uint32_t)rec.inc[j]);
        a->sums.accdec[j] = (int32_t)((uint32_t)a->sums.accdec[j] + (uint32_t)acc[j]);
    }
    a->sums.stop = got && rec.stop;
    a->loaded = 1;
    return 1;
}

/* One servo period of the chain: 1 and its increments, or 0 when it is at
 * rest with nothing to interpolate (nothing changed: it may be asked again). */
static int produce(struct ncp_adcai *a, int32_t inc[NCP_AXES], struct ncp_adcai_rough_rec *tag)
{
    a->loaded = 0;
    if (a->k == 0 && !next_record(a))
        return 0;
    ncp_adcai_fine_step(a->fine, inc);
    *tag = a->tag;
    a->k = (a->k + 1) % a->ratio;
    return 1;
}

/* The sample just produced into a->ahead: whether it starts a record. */
static void note_ahead(struct ncp_adcai *a)
{
    a->ahead_rec = a->sums;
    a->ahead_rec.start = (uint8_t)a->loaded;
}

/* The setpoint out goes to the tap with the record its sample started. */
static void tap(struct ncp_adcai *a, const struct ncp_adcai_tap *rec, const int32_t inc[NCP_AXES])
{
    if (!a->tap)
        return;
    struct ncp_adcai_tap t = *rec;
    memcpy(t.pos, a->pos, sizeof t.pos);
    t.moved = 0;
    for (int j = 0; j < NCP_AXES; j++)
        t.moved |= inc[j] != 0;
    a->tap(a->tap_ctx, &t);
}

int ncp_adcai_step(struct ncp_adcai *a, struct ncp_setpoint *out)
{
    static const int32_t none[NCP_AXES];
    memset(out, 0, sizeof *out);
    if (!a->have_ahead) {
        a->have_ahead = produce(a, a->ahead, &a->ahead_tag);
        note_ahead(a);
    }
    if (!a->have_ahead) {
        setpoint(a, none, none, &a->tag, out);
        struct ncp_adcai_tap rest = a->sums;
        rest.start = 0;
        tap(a, &rest, none);
        if (a->finishing) {   /* the job's end, at rest on its last point */
            out->flags = NCP_SP_END;
            return 0;
        }
        out->flags = NCP_SP_STARVED;
        a->st.starved++;
        return 1;
    }
    int32_t inc[NCP_AXES];
    struct ncp_adcai_rough_rec tag = a->ahead_tag;
    struct ncp_adcai_tap rec = a->ahead_rec;
    memcpy(inc, a->ahead, sizeof inc);
    /* a chain at rest now is asked again next time: segments may come meanwhile */
    a->have_ahead = produce(a, a->ahead, &a->ahead_tag);
    note_ahead(a);
    a->ahead_moves = 0;
    for (int j = 0; a->have_ahead && j < NCP_AXES; j++)
        a->ahead_moves |= a->ahead[j] != 0;
    setpoint(a, inc, a->have_ahead ? a->ahead : none, &tag, out);
    tap(a, &rec, inc);
    return 1;
}
