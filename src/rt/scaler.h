/* Time scaling and fine interpolation of the setpoint stream in the position
 * loop (scaler.c). Not part of the public contract. */
#ifndef NCPAR_RT_SCALER_H
#define NCPAR_RT_SCALER_H

#include "ncpar/motion.h"
#include "ncpar/rt.h"

struct nck_scaler {
    struct ncp_setpoint z;     /* the sample before a (fine interpolation's accelerations) */
    struct ncp_setpoint a, b;  /* samples around the read position */
    struct ncp_setpoint c;     /* the sample after b, fetched ahead (have_c) */
    int have_c, have_z;
    double f;                  /* read position between a (0) and b (1) */
    double r;                  /* rate: setpoints per period, 0..1 */
    double rd;                 /* its rate of change, 1/s (jerk-limited rate changes) */
    double decel, period;
    /* Jerk budget of a rate change along the path, mm/s^3: > 0 makes rate
     * changes jerk-limited (S-curve), 0 leaves them linear ramps. */
    double jerk;
    double rd_cap;             /* cap on |rd|, 1/s (S-curve; see nck_scaler_limits) */
    /* the stream's largest acceleration soon, positive and negative (S-curve) */
    double ahead[NCP_AXES], behind[NCP_AXES];
    double vahead[NCP_AXES];   /* and its largest |velocity| */
    double vpath_ahead;        /* and path speed */
    /* Per-axis limits the output's second and third differences must keep
     * (INFINITY: unchecked); the last three outputs for them. */
    double amax[NCP_AXES], jmax[NCP_AXES];
    double last[3][NCP_AXES];
    int nlast;
    /* Fine interpolation: servo periods per stream sample (1: the stream is
     * at the servo rate and is read linearly), and the stream's period. */
    int ratio;
    double tp;
};

void nck_scaler_init(struct nck_scaler *s, const double start[NCP_AXES], double decel,
                     double period);
/* Axis limits from the machine: acceleration always, jerk and jerk-limited
 * rate changes with the S-curve profile. */
void nck_scaler_limits(struct nck_scaler *s, const struct ncp_machine_cfg *cfg);
double nck_scaler_stop_cycles(const struct nck_scaler *s);
/* The stream comes every ratio periods: read it through quintic Hermite
 * interpolation on the samples' velocities and accelerations (see scaler.c). */
void nck_scaler_set_ratio(struct nck_scaler *s, int ratio);
/* How many samples the ring should hold for a full look-ahead (1 without
 * the S-curve): a virtual clock waits for them, a real one cannot. */
size_t nck_scaler_wants(const struct nck_scaler *s, size_t capacity);
/* One period at a rate moving towards target. Returns -1 when the stream ran
 * dry in motion (the output holds the last sample), else 0. */
int nck_scaler_step(struct nck_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out);

#endif
