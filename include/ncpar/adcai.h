/* ADCAI: the NCK variant with acc/dec after interpolation (the distributed-NCK paper, Fig. 3).
 *
 *   segments -> rough interpolator -> [roughIPObuf] -> per-axis ACC/DEC
 *            -> [ACCDECbuf] -> fine interpolator -> [fineIPObuf] -> position control
 *
 * DP2 is the rough interpolator's output, DP3 the ACC/DEC's, DP4 the fine
 * interpolator's. Every stage below DP2 works on one axis's int32 increments
 * in integer nanometres (1e-6 degree for A B C), so an LLC that runs them for
 * its own axis computes bit for bit what the central NCK computes, and the sum
 * of the increments is exactly the (quantised) programmed end point.
 *
 * The three stages are callable one by one; the driver (ncp_adcai_*) chains
 * them for the central NCK and speaks the planner's protocol (ncpar/motion.h).
 * Only the _new calls allocate. */
#ifndef NCPAR_ADCAI_H
#define NCPAR_ADCAI_H

#include <stdint.h>
#include "ncpar/motion.h"

/* Machine length units per increment unit: increments are nanometres. */
#define NCP_ADCAI_UNITS_PER_MM 1e6

static inline int64_t ncp_adcai_quantise(double mm)
{
    double x = mm * NCP_ADCAI_UNITS_PER_MM;
    return (int64_t)(x < 0 ? x - 0.5 : x + 0.5);
}

/* ---- roughIPObuf (DP2) ------------------------------------------------------
 * The paper's payload is `stop` and `inc` (1 + 4N bytes); the rest says which
 * block the record belongs to, for the NCK's trace, aux functions and
 * summary, and never reaches a stage below. */
struct ncp_adcai_rough_rec {
    uint8_t stop;                 /* path control: the axes come to rest after this record */
    int32_t inc[NCP_AXES];        /* nm this rough period */
    uint32_t line, aux;           /* the segment's */
    uint32_t motion;              /* NCP_SP_RAPID / NCP_SP_ARC */
    double tool_z, rev_rpm;
};

/* ---- a. rough interpolator ----------------------------------------------- */

/* Segments it holds waiting (no look-ahead: one would do; a few keep the
 * feeding thread from having to wake every segment). */
#define NCP_ADCAI_ROUGH_QUEUE 16

struct ncp_adcai_rough;

/* period: the rough interpolation period, s ([TRAJ] PLANNING_PERIOD). */
struct ncp_adcai_rough *ncp_adcai_rough_new(const struct ncp_machine_cfg *cfg, double period,
                                            const double start[NCP_AXES]);
void ncp_adcai_rough_free(struct ncp_adcai_rough *r);
int ncp_adcai_rough_full(const struct ncp_adcai_rough *r);
size_t ncp_adcai_rough_queued(const struct ncp_adcai_rough *r);
/* A segment is being interpolated, or one is queued. */
int ncp_adcai_rough_busy(const struct ncp_adcai_rough *r);
void ncp_adcai_rough_push(struct ncp_adcai_rough *r, const struct ncp_seg *s);
/* No segment follows the queued ones for now: the last one ends in an exact
 * stop. ncp_adcai_rough_restart takes that back once the queue ran out. */
void ncp_adcai_rough_finish(struct ncp_adcai_rough *r);
void ncp_adcai_rough_restart(struct ncp_adcai_rough *r);
/* Drops the queue: at rest at pos. */
void ncp_adcai_rough_reset(struct ncp_adcai_rough *r, const double pos[NCP_AXES]);
/* One rough period: 1 and *out filled while there is motion (or a dwell),
 * 0 with a zero record when there is nothing to interpolate. */
int ncp_adcai_rough_step(struct ncp_adcai_rough *r, struct ncp_adcai_rough_rec *out);
/* The queue had run out in the middle of a program (the interpreter behind
 * the chain) and the block that came now makes a corner with the last that
 * needs a stop: 1 once, so that the caller lets the filters drain first. */
int ncp_adcai_rough_late_stop(struct ncp_adcai_rough *r);
/* The path speed the stage gives s: its feed, capped so that no axis exceeds
 * its MAX_VELOCITY and an arc's centripetal acceleration stays within its
 * axes' MAX_ACCELERATION. */
double ncp_adcai_rough_speed(const struct ncp_machine_cfg *cfg, const struct ncp_seg *s);
/* At rest before the next queued move (the stages below drained): take that
 * move's start as where the axes are, for a start the stream did not lead
 * to (after homing, a drop, a reset). 1 when the position changed. */
int ncp_adcai_rough_align(struct ncp_adcai_rough *r);
/* Where it is, in nm (the sum of everything it emitted since reset). */
void ncp_adcai_rough_position(const struct ncp_adcai_rough *r, int64_t pos[NCP_AXES]);

/* ---- b. per-axis ACC/DEC (moving-average filters) --------------------------- */

/* The longest moving-average window ncp_adcai_windows may ask for. */
#define NCP_ADCAI_WINDOW_MAX 65536

/* The windows, in rough periods, that keep every axis of the machine within
 * its MAX_ACCELERATION (and, under PROFILE = scurve, MAX_JERK) for every
 * velocity the rough stage may emit: n[0] the first, n[1] the second (1 =
 * none, trapezoid). All axes get the same windows: unequal delays would bend
 * a straight line. 0, or -1 when a window would exceed NCP_ADCAI_WINDOW_MAX. */
int ncp_adcai_windows(const struct ncp_machine_cfg *cfg, double period, int n[2]);

struct ncp_adcai_accdec;

struct ncp_adcai_accdec *ncp_adcai_accdec_new(int n1, int n2);
void ncp_adcai_accdec_free(struct ncp_adcai_accdec *f);
void ncp_adcai_accdec_reset(struct ncp_adcai_accdec *f);
/* One rough period: in -> out, every axis. */
void ncp_adcai_accdec_step(struct ncp_adcai_accdec *f, const int32_t in[NCP_AXES],
                           int32_t out[NCP_AXES]);
/* The output has caught up with the input: every window holds one position. */
int ncp_adcai_accdec_drained(const struct ncp_adcai_accdec *f);

/* ---- c. fine interpolator ------------------------------------------------ */

/* ratio servo periods per rough period, smoothed by `windows` moving averages
 * of ratio servo periods (one for the trapezoid, two for the S-curve), so the
 * velocity steps between rough records become ramps within the limits the
 * ACC/DEC kept. */
struct ncp_adcai_fine;

struct ncp_adcai_fine *ncp_adcai_fine_new(int ratio, int windows);
void ncp_adcai_fine_free(struct ncp_adcai_fine *f);
void ncp_adcai_fine_reset(struct ncp_adcai_fine *f);
/* Takes one rough record's increments; then ratio calls of _step. */
void ncp_adcai_fine_load(struct ncp_adcai_fine *f, const int32_t inc[NCP_AXES]);
void ncp_adcai_fine_step(struct ncp_adcai_fine *f, int32_t out[NCP_AXES]);
int ncp_adcai_fine_drained(const struct ncp_adcai_fine *f);

/* ---- the driver: the chain for the central NCK -------------------------------
 * The same protocol as ncp_planner_* (ncpar/motion.h), one setpoint per
 * SERVO period (fine interpolation is its own: the position loop reads the
 * stream at ratio 1). */
struct ncp_adcai;

struct ncp_adcai *ncp_adcai_new(const struct ncp_machine_cfg *cfg, const double start[NCP_AXES]);
void ncp_adcai_free(struct ncp_adcai *a);
int ncp_adcai_full(const struct ncp_adcai *a);
size_t ncp_adcai_queued(const struct ncp_adcai *a);
int ncp_adcai_idle(const struct ncp_adcai *a);
void ncp_adcai_push(struct ncp_adcai *a, const struct ncp_seg *s);
void ncp_adcai_finish(struct ncp_adcai *a);
void ncp_adcai_restart(struct ncp_adcai *a);
void ncp_adcai_reset(struct ncp_adcai *a, const double pos[NCP_AXES]);
int ncp_adcai_step(struct ncp_adcai *a, struct ncp_setpoint *out);
void ncp_adcai_get_stats(const struct ncp_adcai *a, struct ncp_planner_stats *st);

/* What the distributed mode's HLC sends at DP2 and DP3, one per setpoint the
 * driver emits (planner thread), in the stream's order. Sums are of the
 * increments since the reset (a jump of the start at rest is not in them):
 * an LLC feeding their differences to the same stages gets the same
 * increments, and a lost record costs no drift. */
struct ncp_adcai_tap {
    uint8_t start;                /* this setpoint is a rough period's first */
    uint8_t stop;                 /* its rough record's path-control flag */
    uint8_t moved;                /* some axis moves this servo period (a standstill
                                     is a setpoint no axis moves in) */
    int32_t rough[NCP_AXES];      /* rough increments summed, through that record */
    int32_t accdec[NCP_AXES];     /* ACC/DEC output summed, through that record */
    int64_t pos[NCP_AXES];        /* the setpoint, nm (the HLC finds it by this) */
};
void ncp_adcai_set_tap(struct ncp_adcai *a, void (*fn)(void *ctx, const struct ncp_adcai_tap *t),
                       void *ctx);

#endif
