/* The distributed NCK (the distributed-NCK paper): what the HLC (cnc-run run --backend lcm)
 * and its LLCs (cnc-axis) share: channel names, the setpoint message without
 * allocation, and the LLC's receive buffer with its loss accounting.
 *
 * Distribution points, ADCBI (today's planner): DP1 the part program, DP2
 * INTbuf, DP3 LAbuf, DP4 ACCDECbuf (block-level: bursts), DP5 fineIPObuf
 * (period-level: a record every servo period). ADCAI: DP1 the part program,
 * DP2 roughIPObuf, DP3 ACCDECbuf, DP4 fineIPObuf; it has no DP5. Implemented:
 * ADCBI DP5, DP4, DP3, DP2 and DP1; ADCAI DP1-DP4.
 *
 * Positions travel as int32 nanometres: exact and the same for every LLC,
 * +-2.1 m of travel. */
#ifndef NCPAR_DIST_H
#define NCPAR_DIST_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "ncpar/diag.h"
#include "ncpar/motion.h"
#include "ncp_accdec_burst_t.h"
#include "ncp_ax_advert_t.h"
#include "ncp_ax_status_t.h"
#include "ncp_fine_ipo_t.h"
#include "ncp_heartbeat_t.h"
#include "ncp_time_scale_t.h"
#include "ncp_ai_scale_t.h"
#include "ncp_int_burst_t.h"
#include "ncp_la_burst_t.h"
#include "ncp_plan_mark_t.h"
#include "ncp_program_t.h"
#include "ncp_rec_mark_t.h"
#include "ncp_rough_ipo_t.h"
#include "ncp_accdec_ai_t.h"
#include "ncp_clock_probe_t.h"

#define NCP_DIST_HLC_ID 100   /* sender id of the HLC; an LLC's is its axis index + 1 */

/* Channel names: NCP_HLC_<WHAT> and NCP_AX_<L>_<WHAT>. */
#define NCP_DIST_CH_FINE "NCP_HLC_FINE"
#define NCP_DIST_CH_HLC_HEARTBEAT "NCP_HLC_HEARTBEAT"
#define NCP_DIST_CH_ACCDEC "NCP_HLC_ACCDEC"
#define NCP_DIST_CH_SYNC "NCP_HLC_SYNC"
#define NCP_DIST_CH_LA "NCP_HLC_LA"         /* ADCBI DP3 */
#define NCP_DIST_CH_INT "NCP_HLC_INT"       /* ADCBI DP2 */
#define NCP_DIST_CH_STEPS "NCP_HLC_STEPS"   /* ADCBI DP2 */
#define NCP_DIST_CH_PROGRAM "NCP_HLC_PROGRAM" /* ADCBI DP1 */
#define NCP_DIST_CH_SCALE "NCP_HLC_SCALE"   /* block-level points: time_scale_t */
#define NCP_DIST_CH_CLOCK "NCP_HLC_CLOCK"   /* answers to the LLCs' clock probes */
enum ncp_dist_ax_ch { NCP_DIST_AX_ADVERT, NCP_DIST_AX_STATUS, NCP_DIST_AX_HEARTBEAT,
                      NCP_DIST_AX_RESEND, NCP_DIST_AX_CLOCK };
/* "NCP_AX_<L>_ADVERT" etc. into buf (32 bytes are enough). */
void ncp_dist_ax_channel(char *buf, size_t size, int axis, enum ncp_dist_ax_ch what);
/* The clock probes travel on the LCM URL's group and the port after its
 * (url NULL or "": as ncp_msg_open resolves it): the threads that stamp
 * them then wake for them alone, not for every setpoint and status. 128
 * bytes are enough; NCP_OK, or why not in d. */
int ncp_dist_clock_url(const char *url, char *buf, size_t size, struct ncp_diag *d);

/* The ADCAI points the lcm backend streams at. DP4 (fineIPObuf) is the same
 * message as ADCBI's DP5: every servo period's setpoints, so the LLCs need
 * not know which variant made them; DP1 sends the program as ADCBI's does. */
static inline int ncp_dist_adcai_dp(int dp) { return dp >= 1 && dp <= 4; }

/* nm <-> mm; out of the int32 range: -1. */
int ncp_dist_mm_to_nm(double mm, int32_t *nm);
static inline double ncp_dist_nm_to_mm(int32_t nm) { return (double)nm * 1e-6; }

/* ---- fine_ipo_t without the generated decoder's malloc ------------------- */
struct ncp_dist_fine {
    int32_t seq;
    int16_t sender;
    int64_t t_ns;
    int8_t n;
    int32_t pos_nm[NCP_AXES];
};
/* Before any real-time use: the type's fingerprint is computed once here. */
void ncp_dist_init(void);
/* Encoded length, or -1 when it does not fit. */
int ncp_dist_encode_fine(uint8_t *buf, size_t size, const struct ncp_dist_fine *f);
/* 0, or -1 for anything that is not exactly one fine_ipo_t of at most
 * NCP_AXES axes. */
int ncp_dist_decode_fine(const uint8_t *buf, size_t len, struct ncp_dist_fine *f);

/* ---- the LLC's setpoint buffer ------------------------------------------
 * Setpoints are kept by the period they are for (t_ns) and played at a fixed
 * delay behind the HLC; sequence numbers find what went missing. */
#define NCP_DIST_RX_SLOTS 64
/* An LLC plays period t at t + (this + 0.5) periods: room for the HLC's
 * wake-up latency and the wire, and for bridging a lost period. */
#define NCP_DIST_PLAY_DELAY 3

enum ncp_dist_rx_verdict {
    NCP_DIST_RX_NEW,        /* kept */
    NCP_DIST_RX_DUPLICATE,  /* its period is already held: ignored */
    NCP_DIST_RX_STALE,      /* for a period already played (or too old): ignored */
    NCP_DIST_RX_EARLY       /* too far ahead for the buffer: ignored */
};

struct ncp_dist_rx {
    int64_t period_ns;
    int have_seq;
    int32_t top_seq;        /* highest sequence number seen */
    int64_t played_t;       /* the period played last (0: none yet) */
    int32_t last_nm;        /* what was played last (held through gaps) */
    int primed;
    struct { int64_t t_ns; int32_t nm; } slot[NCP_DIST_RX_SLOTS];
    uint32_t lost, stale, duplicate, held, bridged, early, reordered;
};

void ncp_dist_rx_init(struct ncp_dist_rx *r, int64_t period_ns, int32_t start_nm);
/* A received setpoint for this LLC's axis. */
enum ncp_dist_rx_verdict ncp_dist_rx_put(struct ncp_dist_rx *r, int32_t seq, int64_t t_ns,
                                         int32_t nm);
/* The setpoint of period t_ns: the one received; else, once setpoints have
 * started to come, the point on the way to the next one received (bridged),
 * or with none yet the last one again (held). */
int32_t ncp_dist_rx_play(struct ncp_dist_rx *r, int64_t t_ns);
/* The setpoint of period t_ns without playing it: 1 it is here; 2 it is
 * not, but it is the next to play and a later one is here, *nm then what
 * ncp_dist_rx_play will bridge to; 0 neither. */
int ncp_dist_rx_peek(const struct ncp_dist_rx *r, int64_t t_ns, int32_t *nm);
/* Setpoints held for periods after t_ns. */
int ncp_dist_rx_level(const struct ncp_dist_rx *r, int64_t t_ns);

/* ---- block-level points: ACCDECbuf records (ADCBI DP4) -------------------
 * The HLC numbers every record it taps from its planner from 0 and sends them
 * in bursts of up to NCP_DIST_BURST; an LLC keeps them by number in a ring
 * until its interpolator has run them. */
#define NCP_DIST_BURST 10
/* Records an LLC holds: the HLC's planner starts a segment (and taps its
 * record) at most [PLANNER] SETPOINT_RING periods (1024) before the position
 * loop plays its first sample, so at most that many segments are ever ahead
 * of an LLC; the HLC holds back bursts an LLC has no room for. */
#define NCP_DIST_RECS 2048

void ncp_dist_rec_encode(const struct ncp_accdec *a, ncp_accdec_rec_t *r);
void ncp_dist_rec_decode(const ncp_accdec_rec_t *r, struct ncp_accdec *a);

/* ---- ADCBI DP3 (LAbuf) and DP2 (INTbuf) records (blocks.c) -------------- */
/* DP2: a call the HLC's planner got, after `step` of its steps. */
struct ncp_dist_op {
    int op;                 /* NCP_INT_REC_T_PUSH .. DROP */
    int32_t step;
    struct ncp_seg s;       /* PUSH: the block; RESET: the position in s.end */
};
void ncp_dist_seg_encode(const struct ncp_seg *s, ncp_seg_rec_t *r);
void ncp_dist_seg_decode(const ncp_seg_rec_t *r, struct ncp_seg *s);
void ncp_dist_la_encode(const struct ncp_la *la, ncp_la_rec_t *r);
void ncp_dist_la_decode(const ncp_la_rec_t *r, struct ncp_la *la);
void ncp_dist_op_encode(const struct ncp_dist_op *o, ncp_int_rec_t *r);
void ncp_dist_op_decode(const ncp_int_rec_t *r, struct ncp_dist_op *o);

/* DP1: a program file's FNV-1a hash and size (-1: cannot be read), so an LLC
 * knows it reads the HLC's program. */
uint64_t ncp_dist_file_hash(const char *path, int64_t *size);

/* What one place of an LLC's ring holds: the record of its point. */
union ncp_dist_rec {
    struct ncp_accdec a;    /* DP4 (and DP2's own planner's records) */
    struct ncp_la la;       /* DP3 */
    struct ncp_dist_op op;  /* DP2 */
};

struct ncp_dist_recs {
    int32_t num[NCP_DIST_RECS];   /* the record held in each place (-1: none) */
    union ncp_dist_rec *rec;      /* NCP_DIST_RECS of them, allocated once */
    int32_t next;                 /* the next record the interpolator takes */
    int32_t have;                 /* all records below this are here or taken */
    int32_t top;                  /* one past the highest number received */
    uint32_t stale, duplicate, early, gaps;
};
/* 0, or -1 out of memory. */
int ncp_dist_recs_init(struct ncp_dist_recs *q);
void ncp_dist_recs_free(struct ncp_dist_recs *q);
/* A received record (kept, or counted stale, duplicate or too early). */
void ncp_dist_recs_put(struct ncp_dist_recs *q, int32_t num, const union ncp_dist_rec *r);
/* The next record if it is here (1), else 0. */
int ncp_dist_recs_peek(const struct ncp_dist_recs *q, union ncp_dist_rec *r);
/* The interpolator is done with the next record. */
void ncp_dist_recs_pop(struct ncp_dist_recs *q);
/* Every record below num is void (the HLC's abort dropped them): neither
 * run nor asked for again. */
void ncp_dist_recs_skip(struct ncp_dist_recs *q, int32_t num);
static inline int ncp_dist_recs_level(const struct ncp_dist_recs *q) { return q->have - q->next; }

/* ---- ADCAI's period-level points DP2 and DP3 (ai.c) -------------------
 * One message per rough period with every axis's increments summed through
 * that period's record: rough_ipo_t (DP2, with the path-control flag) or
 * accdec_ai_t (DP3). Decoded by hand, as fine_ipo_t, for the LLC's loop. */
#define NCP_DIST_CH_ROUGH "NCP_HLC_ROUGH"
#define NCP_DIST_CH_ACCDEC_AI "NCP_HLC_ACCDEC_AI"
#define NCP_DIST_CH_AI_SCALE "NCP_HLC_AI_SCALE"   /* ai_scale_t: the HLC's read position */

struct ncp_dist_ai {
    int32_t seq;
    int16_t sender;
    int64_t k;                   /* the stream index of its first sample */
    int32_t job;                 /* the HLC's aborts before it */
    int8_t flag;                 /* DP2 only */
    int8_t n;
    int32_t sum_nm[NCP_AXES];
};
/* Before any real-time use: the types' fingerprints. */
void ncp_dist_ai_init(void);
/* dp 2 or 3: encoded length, or -1 when it does not fit. */
int ncp_dist_encode_ai(uint8_t *buf, size_t size, int dp, const struct ncp_dist_ai *r);
/* 0, or -1 for anything that is not exactly one such message. */
int ncp_dist_decode_ai(const uint8_t *buf, size_t len, int dp, struct ncp_dist_ai *r);

/* ---- the common time base (clock.c) ------------------------------------
 * Each LLC probes the HLC's clock (clock_probe_t: t1 and t4 on its clock, t2
 * and t3 on the HLC's) and keeps the last NCP_DIST_CLOCK_WINDOW probes. Of
 * those, the one with the shortest round trip waited least in queues and
 * wake-ups, so its offset is the estimate (NTP's clock filter); the true
 * offset is within half its round trip of it when the two ways' delays
 * differ. */
#define NCP_DIST_CLOCK_WINDOW 8

struct ncp_dist_clock {
    struct { int64_t offset_ns, rtt_ns; } probe[NCP_DIST_CLOCK_WINDOW];
    int n, next;
};

struct ncp_dist_clock_est {
    int64_t offset_ns;      /* the HLC's clock minus this one's */
    int64_t rtt_ns;         /* the chosen probe's round trip */
    int64_t jitter_ns;      /* RMS of the window's offsets about the estimate */
    int probes;             /* in the window */
};

void ncp_dist_clock_init(struct ncp_dist_clock *c);
/* One answered probe: 0, or -1 for times that cannot be (the HLC took
 * longer than the whole round trip), which are not kept. */
int ncp_dist_clock_add(struct ncp_dist_clock *c, int64_t t1, int64_t t2, int64_t t3, int64_t t4);
/* 0 with the estimate, -1 with no probe yet. */
int ncp_dist_clock_estimate(const struct ncp_dist_clock *c, struct ncp_dist_clock_est *e);
/* The offset an LLC applies, moved toward target by at most max_step: a grid
 * in motion is slewed, never stepped. */
int64_t ncp_dist_clock_slew(int64_t applied, int64_t target, int64_t max_step);

/* The probes travel on a socket of their own (the LCM URL's next port:
 * ncp_dist_clock_url), read by a thread of their own that blocks in poll()
 * and stamps each as it reads it: the position loops read their sockets
 * once a period, which would add up to a period of one-sided delay to every
 * round trip. open: the socket, with the run's loss injection (subscribe,
 * then run); run: the thread, which polls while `run` holds; close: joins
 * it and closes the socket (after a failed open or run too). */
struct ncp_msg;

/* The transport's options as [LCM] says (URL, CHANNEL_PREFIX, the key file
 * as ncp_auth_key_path resolves KEY_FILE, INTERFACE, STATUS_NEEDS_KEY,
 * MAX_AGE_MS); the caller may change url, prefix and create_key after.
 * 0, or an error with d set. */
#include "ncpar/msg.h"
struct ncp_dist_msg_opts {
    struct ncp_msg_opts opts;
    char key_file[512];
};
int ncp_dist_msg_opts(const struct ncp_lcm_cfg *l, struct ncp_dist_msg_opts *o,
                      struct ncp_diag *d);

struct ncp_dist_probe_io {
    struct ncp_msg *msg;
    pthread_t thread;
    atomic_int run;
    int started;
};
int ncp_dist_probe_io_open(struct ncp_dist_probe_io *io, const struct ncp_lcm_cfg *l,
                           const char *lcm_url, uint64_t seed, struct ncp_diag *d);
int ncp_dist_probe_io_run(struct ncp_dist_probe_io *io, void *(*body)(void *), void *arg,
                          struct ncp_diag *d);
void ncp_dist_probe_io_close(struct ncp_dist_probe_io *io);
/* CLOCK_REALTIME minus CLOCK_MONOTONIC now: CLOCK = ptp's time base, which
 * phc2sys keeps on the grandmaster's. */
int64_t ncp_dist_realtime_offset(void);

#endif
