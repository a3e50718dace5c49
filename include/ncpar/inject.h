/* Timing faults injected into the real position loop: deadline misses, lost
 * setpoints and feedback, sampling, I/O and feedback latency, wake-up jitter.
 * What a user's host or network would do to the loop, made reproducible: every
 * draw comes from a seeded generator of this module, one stream per kind, so a
 * seed gives the same faults cycle for cycle whatever else is injected.
 *
 * Also what the loop does about them: the setpoint a servo uses when the
 * period's own is late or lost (MISS_POLICY), and the safety limits on misses
 * that stop the machine. Everything called per cycle is real-time safe: no
 * allocation, no locks, no system calls. */
#ifndef NCPAR_INJECT_H
#define NCPAR_INJECT_H

#include <stddef.h>
#include <stdint.h>

#define NCP_INJECT_AXES 9            /* = NCP_AXES (motion.h includes this header) */
#define NCP_INJECT_AT_MAX 64         /* miss@CYCLE specs per run */
#define NCP_INJECT_WINDOW_MAX 100000 /* [RT] MISS_WINDOW, cycles */
#define NCP_INJECT_FB_HISTORY 100    /* periods of plant history for delay-feedback */

/* The kinds, as bits of a period's event and of the kinds configured. */
enum ncp_inject_kind {
    NCP_INJ_MISS = 1u << 0,      /* the setpoint came too late to be used */
    NCP_INJ_LOSE_SP = 1u << 1,   /* the setpoint never came */
    NCP_INJ_LOSE_FB = 1u << 2,   /* the feedback sample never came: the last one is used */
    NCP_INJ_LATENCY = 1u << 3,   /* sampling latency */
    NCP_INJ_IO = 1u << 4,        /* input-output latency (sample to actuation) */
    NCP_INJ_JITTER = 1u << 5,    /* wake-up jitter */
    NCP_INJ_DELAY_FB = 1u << 6,  /* feedback older than the sampling instant */
    NCP_INJ_LATE = 1u << 7,      /* sampling + I/O latency reached the period's end */
};

enum ncp_miss_policy {
    NCP_MISS_HOLD,          /* the last setpoint used (what a plain drive does) */
    NCP_MISS_EXTRAPOLATE,   /* straight on from the last two setpoints received */
    NCP_MISS_EXTRAPOLATE2,  /* along the parabola through the last three */
    NCP_MISS_TIMESTAMPED,   /* time-stamped setpoints, one period ahead, interpolated
                               at the receiver's own sampling instant */
};

struct ncp_inject_cfg {
    unsigned kinds;                  /* NCP_INJ_* given */
    double miss_ratio, lose_sp_ratio, lose_fb_ratio;   /* per period, 0..1 */
    uint64_t miss_at[NCP_INJECT_AT_MAX];
    uint32_t miss_at_axes[NCP_INJECT_AT_MAX];   /* miss@CYCLE:AXES (bit per axis), 0 = all */
    int n_miss_at;
    double lat_min_s, lat_max_s;     /* uniform; equal for latency=US */
    double io_s, delay_fb_s;
    double jitter_s;                 /* the bound */
    int jitter_normal;               /* 0 uniform in [0, bound]; 1 normal, mean bound/2,
                                        sigma bound/6, clipped to [0, bound] */
    uint64_t seed;
    /* [RT] */
    int policy;                      /* enum ncp_miss_policy */
    int per_axis;                    /* SETPOINT_FRAMES = per-axis: each axis' setpoint
                                        travels in its own frame, so a miss or a lost
                                        setpoint is drawn for each axis on its own and
                                        hits that axis alone (the paper's servo nodes);
                                        0: one frame carries every axis */
    int max_consecutive;             /* MAX_CONSECUTIVE_MISSES, 0 = no limit */
    double max_ratio;                /* MAX_MISS_RATIO over window cycles, 0 = no limit */
    int window;                      /* MISS_WINDOW (1000) */
};

void ncp_inject_cfg_default(struct ncp_inject_cfg *c);
/* Adds a comma-separated list of specs (the names of --inject and [INJECT]
 * SPEC). 0, or -1 with why naming the spec that is wrong and what it should be. */
int ncp_inject_parse(struct ncp_inject_cfg *c, const char *list, char *why, size_t len);
/* One key of the machine INI: [INJECT] SPEC / SEED, [RT] MISS_POLICY /
 * MAX_CONSECUTIVE_MISSES / MAX_MISS_RATIO / MISS_WINDOW. 1 taken, 0 not one
 * of these keys, -1 bad value (why says what is wanted). */
int ncp_inject_ini_key(struct ncp_inject_cfg *c, const char *sec, const char *k, const char *v,
                       char *why, size_t len);
/* Before the run: checks what depends on the servo period (delay-feedback
 * is held for a bounded number of periods) and that miss@CYCLE:AXES has
 * per-axis frames to act on. 0, or -1 with why. */
int ncp_inject_check(const struct ncp_inject_cfg *c, double period_s, char *why, size_t len);
const char *ncp_miss_policy_name(int policy);

/* ---- per period ----------------------------------------------------------- */

/* What one period got. */
struct ncp_inject_ev {
    uint32_t what;                   /* NCP_INJ_* that acted */
    double sample_s;                 /* jitter + sampling latency: when the servo samples */
    double io_s;                     /* sample to actuation */
    double delay_fb_s;               /* the feedback is this much older than the sample */
    double jitter_s;                 /* the jitter part of sample_s */
    uint32_t miss_axes, lose_axes;   /* axes whose setpoint missed / was lost (bit per
                                        axis); every axis when one frame carries them */
    int per_axis;                    /* drawn per axis: the trace names the axes */
};

struct ncp_xoshiro {
    uint64_t s[4];
};

enum { NCP_INJ_STREAM_MISS, NCP_INJ_STREAM_LOSE_SP, NCP_INJ_STREAM_LOSE_FB,
       NCP_INJ_STREAM_LATENCY, NCP_INJ_STREAM_JITTER, NCP_INJ_STREAMS };

struct ncp_inject {
    struct ncp_inject_cfg cfg;
    double period_s;
    struct ncp_xoshiro rng[NCP_INJ_STREAMS];
};

void ncp_xoshiro_seed(struct ncp_xoshiro *r, uint64_t seed);
uint64_t ncp_xoshiro_next(struct ncp_xoshiro *r);
double ncp_xoshiro_uniform(struct ncp_xoshiro *r);   /* [0, 1) */
double ncp_xoshiro_normal(struct ncp_xoshiro *r);    /* N(0, 1) */

void ncp_inject_init(struct ncp_inject *in, const struct ncp_inject_cfg *c, double period_s);
/* The events of period `cycle` (the position loop's count since its start).
 * Each kind draws from its own stream once per period, used or not. */
void ncp_inject_period(struct ncp_inject *in, uint64_t cycle, struct ncp_inject_ev *ev);
/* "-" or the events joined by '+', e.g. "miss+jit=12.500": the trace column. */
int ncp_inject_format(const struct ncp_inject_ev *ev, char *buf, size_t len);

/* ---- the setpoint a servo uses (the receiver's side) ---------------------- */

struct ncp_inject_rx {
    int policy;
    int n;                                    /* setpoints received so far, up to 3 kept */
    double c[3][NCP_INJECT_AXES];             /* newest first */
    int64_t k[3];
    double ahead[NCP_INJECT_AXES];            /* timestamped: the next period's, received */
    int have_ahead;
    double last[NCP_INJECT_AXES];             /* what the servo used last period */
    int have_last;
};

void ncp_inject_rx_init(struct ncp_inject_rx *rx, int policy);
/* Period k: cmd and next are the interpolator's setpoints for k and k + 1;
 * arrived says whether k's reached the servo in time; frac is where in the
 * period the servo samples (0..1). use/use_next get what the servo runs on. */
void ncp_inject_rx_take(struct ncp_inject_rx *rx, int64_t k, int arrived, const double *cmd,
                        const double *next, double frac, int axes, double *use,
                        double *use_next);

/* What a run got, for its summary: periods each kind acted in (by bit
 * number of enum ncp_inject_kind), the periods that missed, and the limit
 * that stopped it. */
#define NCP_INJ_KINDS 8
struct ncp_inject_report {
    uint64_t count[NCP_INJ_KINDS];
    uint64_t misses;         /* injected, late, lost setpoints and the real clock's */
    int trip;                /* enum ncp_inject_trip */
    uint64_t trip_cycle;
    uint32_t trip_line;      /* the block in progress */
    int trip_run, trip_in_window;
};
/* One line for the summary ("" when nothing was injected). */
void ncp_inject_summary(const struct ncp_inject_cfg *c, const struct ncp_inject_report *r,
                        char *buf, size_t len);

/* What stopped the run: the limit, the cycle and its time, for a machinist. */
void ncp_inject_trip_text(const struct ncp_inject_cfg *c, const struct ncp_inject_report *r,
                          double period_s, char *buf, size_t len);

/* ---- safety limits on misses ---------------------------------------------- */

enum ncp_inject_trip { NCP_TRIP_NONE, NCP_TRIP_CONSECUTIVE, NCP_TRIP_RATIO };

struct ncp_inject_guard {
    int max_consecutive, window;
    double max_ratio;
    int consecutive, in_window;
    uint64_t seen;                            /* periods added */
    uint64_t bits[(NCP_INJECT_WINDOW_MAX + 63) / 64];
};

void ncp_inject_guard_init(struct ncp_inject_guard *g, const struct ncp_inject_cfg *c);
/* One period, missed or not: the limit it trips (enum ncp_inject_trip). */
int ncp_inject_guard_add(struct ncp_inject_guard *g, int missed);

#endif
