/* The machine as the position loop drives it: the spindle, coolant, I/O,
 * the aux pack being applied and the synchronised run it moves. */
#ifndef NCPAR_NCK_MACHINE_H
#define NCPAR_NCK_MACHINE_H

#include "job_msgs.h"

enum nck_sync_phase { NCK_SYNC_IDLE, NCK_SYNC_ARRIVE, NCK_SYNC_AT_SPEED, NCK_SYNC_INDEX,
                      NCK_SYNC_FOLLOW, NCK_SYNC_TAP_IN, NCK_SYNC_TAP_OUT, NCK_SYNC_TAP_TURN,
                      NCK_SYNC_PLACE, NCK_SYNC_DONE };
/* The loop's state of the run it moves (its thread only). */
struct nck_sync_state {
    int phase;                 /* enum nck_sync_phase */
    struct nck_sync_run run;
    double total;              /* the run's length, mm */
    double s, v;               /* distance along the run and its speed */
    double acc, vmax;          /* along the path, within every axis's limits */
    double index;              /* the spindle turn (whole) its index came at */
    double rev_last;           /* the spindle angle the period before, turns */
    int sgn;                   /* the spindle's direction at the start: turns count this way */
    double rpm_cmd;            /* G33.1: the speed the tap went in at */
};

/* The machine as the position loop drives it (its thread only). */
struct nck_mach {
    double rpm_cmd;            /* the program's: signed, before the override */
    double rpm;                /* actual, signed */
    double rev;                /* spindle angle in turns since start */
    int orienting;             /* 1 braking, 2 turning to the angle */
    double orient_to;          /* turns, 0..1 */
    int orient_dir, orient_sign;
    int mist, flood, tool, prepared;
    uint64_t dout;
    double aout[NCP_AIO_MAX];
    int en[4];                 /* enum nck_enable: 1 enabled (the default) */
    uint32_t seq_reached;      /* the highest aux of the samples taken */
    struct nck_aux_pack pack;  /* the pack being applied */
    int have_pack, at;         /* and its next action */
    struct nck_aux_pack ahead; /* the next pack, taken off the ring, not due yet */
    int have_ahead;
    int wait;                  /* enum nck_wait */
    uint32_t waits;            /* waits begun */
    uint32_t wait_line;
    int64_t wait_since;
    uint64_t resume_used;
    int in_last;               /* M66 L1/L2: the input's previous value */
    int spun;                  /* the spindle was stepped at spun_at */
    int64_t spun_at;
};

#endif
