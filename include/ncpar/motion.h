/* Motion: canonical calls -> machine-space segments, look-ahead planner and
 * the interpolator that samples it every servo period, within the limits of
 * the machine's configuration (ncpar/config.h).
 * All lengths in mm, times in s, velocities in mm/s, machine coordinates. */
#ifndef NCPAR_MOTION_H
#define NCPAR_MOTION_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/canon.h"
#include "ncpar/config.h"
#include "ncpar/diag.h"
#include "ncpar/rt.h"

/* The largest feed override cnc-run takes (200 %). Corner blends are planned
 * for it, as LinuxCNC plans them for its MAX_FEED_OVERRIDE. */
#define NCP_FEED_OVERRIDE_MAX 2.0

/* ---- segments -------------------------------------------------------------- */

/* NCP_SEG_PARAB: a G64 corner between two lines (src/motion/blend.c), the
 * quadratic curve from start through the pull of the corner (center) to end,
 * at a constant acceleration vector when run at a constant speed. */
enum ncp_seg_kind { NCP_SEG_LINE, NCP_SEG_ARC, NCP_SEG_DWELL, NCP_SEG_PARAB };

enum ncp_seg_term { NCP_TERM_STOP, NCP_TERM_EXACT_PATH, NCP_TERM_CONTINUOUS };

/* Spindle-synchronised moves: a thread line (G33, G76), a rigid tap's way
 * in (G33.1) and its way back out (the NCK's position loop reverses the
 * spindle and follows it back; the map makes the segment for the path's
 * sake: soft limits, the time estimate). */
enum ncp_seg_sync { NCP_SYNC_NONE, NCP_SYNC_THREAD, NCP_SYNC_TAP, NCP_SYNC_TAP_OUT };

struct ncp_seg {
    uint8_t kind;          /* enum ncp_seg_kind */
    uint8_t term;          /* enum ncp_seg_term: how this segment ends */
    uint8_t traverse;      /* G0: runs at the machine's maximum velocity */
    /* length (and feed) measured along A B C, in degrees: a move of rotary
     * axes only (LinuxCNC's rule: along X Y Z when they move) */
    uint8_t angular;
    /* enum ncp_seg_sync: a move tied to the spindle's angle (G33, G76's
     * passes, G33.1), which the position loop runs itself */
    uint8_t sync;
    uint32_t line;         /* source line */
    /* The machine functions sent before this segment (NCK): the sequence
     * number of the last, applied when its samples are reached. */
    uint32_t aux;
    double start[NCP_AXES], end[NCP_AXES];
    double length;         /* path length (0 for dwell): along X Y Z, else A B C */
    double feed;           /* requested path velocity (override applied), mm/s */
    /* the path velocity a G64 corner's blend is sized for: the feed at
     * NCP_FEED_OVERRIDE_MAX, so the path cut never depends on the override
     * in force (0 = feed) */
    double blend_feed;
    double tolerance;      /* G64 P, mm (0 = none) */
    double merge_tol;      /* G64 Q, mm: the planner merges a run of nearly
                              collinear feed lines into one (0 = off) */
    double dwell;          /* s, NCP_SEG_DWELL only */
    double tool_z;         /* G43's tool length (Z) in force, mm: the kinematics' tool
                              offset for this segment's samples */
    double pitch;          /* sync: mm along the path per spindle turn */
    /* G95: the spindle speed (rpm) feed was planned for; the position loop
     * scales the path speed by the actual speed over it (0: not per turn) */
    double rev_rpm;
    /* arcs and helices: p(l) = c + r(l)(cos(A l) u + sin(A l) w) + n h l, l in [0,1],
     * in X Y Z; the other axes move linearly in l from start to end.
     * NCP_SEG_PARAB: center is the programmed corner C and, with l = dist /
     * length, p(l) = (1-l)^2 start + 2 l (1-l) C + l^2 end: its tangent runs
     * from the line before's direction to the line after's, both unit in
     * X Y Z when C sits length / 2 from start and from end. An uneven one
     * (r0 = |C - start| and r1 = |end - C| differ, both > 0; 0 = even) has
     * length r0 + r1 and dist = 2 r0 l + (r1 - r0) l^2, so its tangent is
     * unit at both ends; run from entry speed v0 to r1 / r0 v0 at a constant
     * path acceleration, l moves at a constant rate and every axis at a
     * constant acceleration (ncp_seg_ratio). */
    double center[3], normal[3], u[3], w[3];
    double r0, r1, angle, axial;
};

/* A line's length as LinuxCNC measures a path: along X Y Z when they move,
 * else along A B C in degrees (s->angular). */
void ncp_seg_set_length(struct ncp_seg *s);
/* Does s move any axis but X Y Z? (Corners of such moves are not blended.) */
int ncp_seg_moves_other(const struct ncp_seg *s);
/* Position at path distance s (0..length) and the tangent there (may be NULL):
 * per axis its change per unit of path length, so the X Y Z part is a unit
 * vector when the path runs along X Y Z. On NCP_SEG_PARAB "length" is the
 * curve's parameter: the tangent is shorter than a unit inside it (the tool
 * moves slower than the parameter, so the feed holds). */
void ncp_seg_eval(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                  double tangent[NCP_AXES]);
/* NCP_SEG_PARAB (length > 0): per axis the most its position changes per
 * unit of the curve's parameter (rate: the larger of the two lines' shares,
 * where the tangent starts and ends) and its constant second derivative
 * (curv = |u2 - u1| / length): at parameter speed v the axis moves at most
 * v rate and its turn takes v^2 curv of its acceleration. */
void ncp_seg_parab_rates(const struct ncp_seg *s, double rate[NCP_AXES], double curv[NCP_AXES]);
/* An uneven corner parabola's exit over entry speed (r1 / r0), else 0: such a
 * blend is run only as a constant-acceleration ramp from v0 to ratio v0, on
 * which axis j accelerates at v0^2 curv_j (ncp_seg_parab_rates: there curv is
 * |r1/r0 u2_j - u1_j| / (2 r0), per square of the entry speed). */
double ncp_seg_ratio(const struct ncp_seg *s);

/* ---- kinematics along segments (kins_seg.c) -------------------------------
 * The planner works on axes; the joints follow through cfg->kins. These keep
 * the joints within their [JOINT_n] limits along the path. */

/* Samples s through the inverse kinematics: a joint beyond its MIN_LIMIT or
 * MAX_LIMIT anywhere along it is -NCP_ERR_LIMIT with d naming joint, value
 * and limit at s->line; else 0. */
int ncp_kins_seg_check(const struct ncp_machine_cfg *c, const struct ncp_seg *s,
                       struct ncp_diag *d);
/* Lowers the path speed cap *vmax and acceleration *acc so that every
 * joint keeps its MAX_VELOCITY and MAX_ACCELERATION along s (a quarter of
 * the acceleration for the path's curvature in joint space, half for the
 * path acceleration, the rest for corners: ncp_kins_junction_cap). */
void ncp_kins_seg_caps(const struct ncp_machine_cfg *c, const struct ncp_seg *s, double *vmax,
                       double *acc);
/* The speed at the junction of a and b at which each joint's velocity step
 * stays within share of its acceleration over one period. */
double ncp_kins_junction_cap(const struct ncp_machine_cfg *c, const struct ncp_seg *a,
                             const struct ncp_seg *b, double share, double period);

/* ---- canonical calls -> segments ------------------------------------------- */

/* A G5.3 NURBS being drawn (src/motion/nurbs_eval.h): the last points in, as
 * w x, w y, w, in a ring indexed by point number. */
#define NCP_NURBS_MAX_ORDER 28
#define NCP_NURBS_WINDOW 32
struct ncp_nurbs_stream {
    uint32_t count, received;
    int order;
    uint32_t span, step;          /* the next line: span's step-th of NCP_SPLINE_STEPS */
    double pt[NCP_NURBS_WINDOW][3];
};

struct ncp_canon_map {
    const struct ncp_machine_cfg *cfg;
    double scale;           /* mm per program unit */
    double g5x[6], g92[6], tool[6]; /* mm */
    double rotation;        /* XY rotation, degrees */
    int plane;              /* 0 XY, 1 YZ, 2 XZ */
    double feed;            /* F in mm: per minute, or per turn under G95 */
    double feed_deg;        /* F as degrees, for moves of rotary axes only */
    double feed_override;   /* 1.0 = 100 % */
    /* Feeds tied to the spindle: G95 (F per turn), G33/G33.1/G76 (the pitch
     * per turn, while synchronised), at the spindle's speed: S in rpm, or
     * under G96 the surface speed S at the end point's X as the radius,
     * capped at G96's D. */
    int per_rev;
    double sync_pitch;      /* mm per turn; 0: not synchronised */
    double speed;           /* S as programmed */
    double css_max;         /* > 0: G96 (constant surface speed), rpm cap */
    int spindle_dir;        /* M3 1, M4 -1, M5/M19 0: a feed tied to a stopped spindle
                               would never move, so it is refused */
    /* A call that makes several segments, what ncp_canon_map_more has left:
     * more_left 1, a rigid tap's way back out; more_kind NCP_C_NURBS_POINTS,
     * the rest of a curve (G5, G5.1, G5.3) in lines. */
    int more_left, more_kind;
    uint32_t more_line;
    double more_back[NCP_AXES];   /* RIGID_TAP: where the tap started, mm */
    double more_z;                /* the curve's Z, program units */
    struct ncp_nurbs_stream nurbs; /* the curve, its points as they come */
    int term;               /* enum ncp_seg_term */
    double tolerance;       /* mm */
    double merge_tol;       /* G64 Q, mm */
    double pos[NCP_AXES];   /* machine position at the end of the last segment */
};

void ncp_canon_map_init(struct ncp_canon_map *m, const struct ncp_machine_cfg *cfg,
                        const double start[NCP_AXES], double feed_override);
/* Feeds one canonical call. Returns 1 and fills *seg when it makes motion (or a
 * dwell), 0 when it only changes state, or minus an error code with d filled
 * (soft-limit violations: -NCP_ERR_LIMIT, d->line = the block's line). */
int ncp_canon_map_op(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
                     struct ncp_seg *seg, struct ncp_diag *d);
/* After a call that made a segment: the next segment the same call makes
 * (1), none left (0), or minus an error code. A rigid tap is two segments
 * (in, back out), a G5/G5.1 spline NCP_SPLINE_STEPS lines along the curve,
 * a G5.3 NURBS as many for each knot span, drawn as its points come in. */
int ncp_canon_map_more(struct ncp_canon_map *m, struct ncp_seg *seg, struct ncp_diag *d);
#define NCP_SPLINE_STEPS 16
/* The inverse of what the map does to a call's X Y Z: a machine position in
 * the program's coordinates and units under the offsets, rotation and units
 * the map holds now (to put an interpreter back where the machine is). */
void ncp_canon_map_to_program(const struct ncp_canon_map *m, const double machine[NCP_AXES],
                              double prog[3]);

/* ---- planner + interpolator ------------------------------------------------ */

struct ncp_setpoint {
    double pos[NCP_AXES];   /* commanded machine position, mm */
    double v;               /* path velocity, mm/s */
    double dir[NCP_AXES];   /* unit tangent (for contour error), 0 at rest */
    uint32_t line;
    uint32_t flags;         /* enum ncp_sp_flags */
    uint32_t aux;           /* the segment's aux: machine functions due by this sample */
    double tool_z;          /* the segment's tool_z */
    double rev_rpm;         /* the segment's (G95: the speed the feed was planned for) */
};

enum ncp_sp_flags { NCP_SP_END = 1u, NCP_SP_STARVED = 2u };
/* What kind of move a setpoint lies on (trace column `motion`, the plot):
 * neither bit = a feed (G1, a G64 corner blend, a dwell, rest). */
enum ncp_sp_motion { NCP_SP_RAPID = 4u, NCP_SP_ARC = 8u };
/* A sample the position loop made itself, following the spindle (G33,
 * G33.1, G76): never in the planner's stream. */
#define NCP_SP_SYNC 16u
#define NCP_SP_MOTION_MASK (NCP_SP_RAPID | NCP_SP_ARC)

struct ncp_planner;

struct ncp_planner *ncp_planner_new(const struct ncp_machine_cfg *cfg,
                                    const double start[NCP_AXES]);
void ncp_planner_free(struct ncp_planner *p);
/* Room for another segment in the look-ahead window? */
int ncp_planner_full(const struct ncp_planner *p);
size_t ncp_planner_queued(const struct ncp_planner *p);
/* No segment is executing: the machine is at rest (or about to start). */
int ncp_planner_idle(const struct ncp_planner *p);
/* Appends a segment and re-plans backwards until a velocity no longer changes.
 * Under G64 Q a feed line may be held back to be joined with the lines after
 * it; ncp_planner_finish lets it go. */
void ncp_planner_push(struct ncp_planner *p, const struct ncp_seg *s);
/* No more segments will come: the queue may be run to its end (a line held
 * back for G64 Q included). */
void ncp_planner_finish(struct ncp_planner *p);
/* After a finished queue has run out (ncp_planner_step returned 0): take
 * segments again, the next one starting from rest (no blend with the last). */
void ncp_planner_restart(struct ncp_planner *p);
/* Drops everything queued: at rest at pos, as if new (statistics kept). */
void ncp_planner_reset(struct ncp_planner *p, const double pos[NCP_AXES]);
/* Advances the interpolator by one servo period and writes the setpoint.
 * Returns 1 while moving or waiting for segments, 0 once everything has run
 * after ncp_planner_finish(). */
int ncp_planner_step(struct ncp_planner *p, struct ncp_setpoint *out);

struct ncp_planner_stats {
    uint64_t segments;      /* segments pushed */
    uint64_t merged;        /* feed lines G64 Q joined to the one before */
    uint64_t replans;       /* segment entry velocities revised by backward passes */
    uint64_t starved;       /* cycles spent at rest waiting for segments */
    double path_length;     /* mm executed */
};
void ncp_planner_get_stats(const struct ncp_planner *p, struct ncp_planner_stats *st);

/* Trapezoid over a distance L from v0 to v1 with cruise cap vmax and accel a
 * (|v1^2 - v0^2| <= 2aL is assumed). Times of the three phases. */
struct ncp_trap {
    double v0, vp, v1, a;
    double t1, t2, t3;      /* accelerate, cruise, decelerate */
    double d1, d2;          /* distance at the end of phase 1 and 2 */
    double length;
    double j;               /* path jerk: > 0 makes the ramps jerk-limited (S-curve) */
};
void ncp_trap_plan(struct ncp_trap *tp, double len, double v0, double v1, double vmax,
                   double a);
double ncp_trap_duration(const struct ncp_trap *tp);
/* The same with jerk-limited ramps (acceleration 0 at both ends of each ramp):
 * PROFILE = scurve. Reuses struct ncp_trap with j > 0; ncp_trap_eval serves both. */
void ncp_scurve_plan(struct ncp_trap *tp, double len, double v0, double v1, double vmax,
                     double a, double j);
/* Distance a jerk-limited change between speeds va and vb takes. */
double ncp_scurve_dist(double va, double vb, double a, double j);
/* Highest speed reachable from v (or: from which v is reachable) within len. */
double ncp_scurve_reach(double v, double len, double a, double j);
/* Distance and velocity at time t (clamped to the duration). */
double ncp_trap_eval(const struct ncp_trap *tp, double t, double *v);

/* ---- the interpolator on its own (exec.c) ---------------------------------
 * One segment as the interpolator runs it, its profile frozen when it starts:
 * the distributed-NCK paper's ACCDECbuf record of the ADCBI NCK. The planner hands these to its
 * own interpolator; an LLC at ADCBI's DP4 receives them and runs the same
 * code, so its samples equal the central run's. */
struct ncp_accdec {
    struct ncp_seg s;
    struct ncp_trap trap;   /* the profile (zero for a dwell) */
    double dur;             /* s */
    uint8_t blend;          /* a G64 corner arc, not a programmed segment */
    /* The planner's interpolator was told "no more" (a stop for an END,
     * SYNC or machine function) before this one came: its stream rests one
     * sample on the stop between them, which an LLC's interpolator, given
     * the records back to back, must rest too (and leave at the HLC's mark:
     * the HLC may have waited there, for the spindle say). */
    uint8_t after_stop;
};

/* Where the interpolator gets its records. next: the record to run after one
 * that ended at speed v0 (0: from rest); 1 filled, 0 none yet, -1 none and no
 * more will come. done: the record running has ended. */
struct ncp_exec_source {
    int (*next)(void *ctx, double v0, struct ncp_accdec *rec);
    void (*done)(void *ctx);
    void *ctx;
};

struct ncp_exec {
    double period;          /* planning period, s */
    int active;             /* cur is running */
    struct ncp_accdec cur;
    double t;               /* time into cur */
    double v_now;           /* path speed at the last sample */
    double pos[NCP_AXES];
    uint32_t line, aux;     /* cur's (ncp_seg.line, .aux) */
    double tool_z;
};

void ncp_exec_init(struct ncp_exec *e, const double start[NCP_AXES], double period);
/* One planning period. Returns 1 while moving or waiting (NCP_SP_STARVED: at
 * rest, no record yet), 0 once the source has said there are no more
 * (NCP_SP_END). A record that ends at speed with none after it stops on its
 * end point with NCP_SP_STARVED set: the source fell behind. */
int ncp_exec_step(struct ncp_exec *e, const struct ncp_exec_source *src,
                  struct ncp_setpoint *out);

/* The look-ahead's word on one segment as its profile is about to be frozen:
 * the distributed-NCK paper's LAbuf of the ADCBI NCK. Beside the block, the limits the look-
 * ahead gave it (cruise cap, path acceleration before and after a corner took
 * its share, jerk, an arc's acceleration bound, curvature and cap) and the end
 * speed it allows (the next segment's entry speed; 0 before a stop). */
struct ncp_la {
    struct ncp_seg s;
    double vmax, acc, acc_full, jerk, a_eff, kappa, a_cap;
    double box_a[3], box_b[3], box_kappa;  /* a fitted arc's per-axis room */
    double v_end;
    uint8_t blend;
    uint8_t after_stop;     /* as ncp_accdec's */
};

/* ADCBI's ACC/DEC stage on its own: the profile of la entered at v0 (the
 * speed the segment before ended with), as the planner freezes it. */
void ncp_la_profile(enum ncp_profile profile, const struct ncp_la *la, double v0,
                    struct ncp_accdec *rec);

/* Every segment the planner starts, as it starts it: its look-ahead record
 * and the profile frozen from it (the HLC of ADCBI's DP3 or DP4 sends one of
 * them on; NULL: none). */
void ncp_planner_set_tap(struct ncp_planner *p,
                         void (*tap)(void *ctx, const struct ncp_la *la,
                                     const struct ncp_accdec *rec),
                         void *ctx);

/* ---- the position loop's reading of the setpoint stream (scaler.c) ---------
 * Time scaling (feed override, feed hold, underruns: the path stays, only the
 * time along it changes) and fine interpolation between planning periods. */
struct ncp_scaler {
    struct ncp_setpoint z;     /* the sample before a (fine interpolation's accelerations) */
    struct ncp_setpoint a, b;  /* samples around the read position */
    struct ncp_setpoint c;     /* the sample after b, fetched ahead (have_c) */
    int have_c, have_z;
    double f;                  /* read position between a (0) and b (1) */
    double r;                  /* rate: setpoints per period, 0..1 */
    double adv;                /* how far the last step read on, in samples (r, but for a
                                * stop landed on): the LLCs of a block-level point follow it */
    double rd;                 /* its rate of change, 1/s (jerk-limited rate changes) */
    double decel, period;
    /* Jerk budget of a rate change along the path, mm/s^3: > 0 makes rate
     * changes jerk-limited (S-curve), 0 leaves them linear ramps. */
    double jerk;
    double rd_cap;             /* cap on |rd|, 1/s (S-curve; see ncp_scaler_limits) */
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
    /* END samples reached (the read position landed on them), each once */
    uint64_t ends;
    int b_counted;
};

void ncp_scaler_init(struct ncp_scaler *s, const double start[NCP_AXES], double decel,
                     double period);
/* Axis limits from the machine: acceleration always, jerk and jerk-limited
 * rate changes with the S-curve profile. */
void ncp_scaler_limits(struct ncp_scaler *s, const struct ncp_machine_cfg *cfg);
double ncp_scaler_stop_cycles(const struct ncp_scaler *s);
/* Drops the stream (the caller has emptied the ring): at rest at pos, rate
 * 0, the configuration (limits, ratio, deceleration) kept. */
void ncp_scaler_rebase(struct ncp_scaler *s, const double pos[NCP_AXES]);
/* The stream comes every ratio periods: read it through quintic Hermite
 * interpolation on the samples' velocities and accelerations (see scaler.c). */
void ncp_scaler_set_ratio(struct ncp_scaler *s, int ratio);
/* The stream jumps by delta at the stop the read position sits on (a run
 * the position loop moved itself, src/nck/sync.c, ends there): that sample,
 * those before it and the outputs remembered move by delta, the samples
 * after it (planned from the new place) stay. */
void ncp_scaler_jump(struct ncp_scaler *s, const double delta[NCP_AXES]);
/* How many samples the ring should hold for a full look-ahead (1 without
 * the S-curve): a virtual clock waits for them, a real one cannot. */
size_t ncp_scaler_wants(const struct ncp_scaler *s, size_t capacity);
/* One period at a rate moving towards target. Returns -1 when the stream ran
 * dry in motion (the output holds the last sample), else 0. */
int ncp_scaler_step(struct ncp_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out);

#endif
