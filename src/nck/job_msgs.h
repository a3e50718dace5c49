/* What the job thread sends down the rings: segments and marks to the
 * planner, machine function packs and synchronised runs to the position loop. */
#ifndef NCPAR_NCK_JOB_MSGS_H
#define NCPAR_NCK_JOB_MSGS_H

#include "ncpar/backend.h"
#include "ncpar/nck.h"

/* The segment ring's messages. END closes a job's motion; SYNC makes the
 * planner run what it has to a stop without ending the job (single block);
 * AUX too, and the stop's sample carries the machine functions (aux) that
 * wait for motion, as LinuxCNC's task waits for motion before them. */
enum { NCK_MSG_SEG, NCK_MSG_END, NCK_MSG_SYNC, NCK_MSG_AUX };
struct nck_seg_msg {
    int kind;
    uint32_t aux;              /* END/SYNC/AUX: machine functions due at the stop */
    /* AUX: after the stop the stream goes on from seg.end (a spindle-
     * synchronised run the position loop moves itself ends there) */
    int jump;
    struct ncp_seg seg;
};

/* ---- machine functions (aux.c, applied by the position loop) -----------------
 * The job thread turns the non-motion calls into aux actions, in packs
 * numbered 1, 2, ... (seq) on their own ring to the position loop. Samples
 * carry the seq of the last pack due by them (ncp_setpoint.aux): the loop
 * applies the packs up to it when it reaches the sample, so a spindle start
 * or an M0 happens where it stands in the program, not when interpreted. A
 * pack that waits for motion is sent after an AUX stop; one that goes with
 * motion (M62/M63/M67) rides on the next segment. */
enum nck_aux_kind {
    NCK_AUX_SPINDLE,       /* v: rpm, signed (M3 +, M4 -, 0 stop) */
    NCK_AUX_ORIENT,        /* v: angle in degrees, i: M19's P; waits until oriented */
    NCK_AUX_AT_SPEED,      /* waits until the spindle is at its speed */
    NCK_AUX_MIST, NCK_AUX_FLOOD,  /* i: on */
    NCK_AUX_DOUT,          /* idx, i: on */
    NCK_AUX_AOUT,          /* idx, v */
    NCK_AUX_WAIT_INPUT,    /* idx, i: mode (L), v: timeout s; a: 1 analog */
    NCK_AUX_PAUSE,         /* i: enum nck_wait (M0, M1, M60); waits for resume */
    NCK_AUX_TOOL,          /* i: the tool; waits for the change */
    NCK_AUX_PREPARE,       /* i: the tool (T) */
    NCK_AUX_ENABLE,        /* i: enum nck_enable, a: on */
    NCK_AUX_PROBE,         /* i: NCP_PROBE_F_*; rides on the probe move, arms the probe */
    NCK_AUX_SYNC,          /* the next run of the sync ring; waits until it has run */
};
enum nck_enable { NCK_EN_FEED_OVERRIDE, NCK_EN_SPEED_OVERRIDE, NCK_EN_FEED_HOLD,
                  NCK_EN_ADAPTIVE };
/* What the loop waits for (nck_fb.wait): 0 nothing. */
enum nck_wait { NCK_WAIT_NONE, NCK_WAIT_M0, NCK_WAIT_M1, NCK_WAIT_M60, NCK_WAIT_TOOL,
                NCK_WAIT_SPINDLE, NCK_WAIT_ORIENT, NCK_WAIT_INPUT, NCK_WAIT_INDEX };
struct nck_aux {
    uint8_t kind, a;
    int16_t idx;
    int32_t i;
    uint32_t line;
    double v;
};
#define NCK_AUX_PACK 6
struct nck_aux_pack {
    uint32_t seq;
    int n;
    struct nck_aux a[NCK_AUX_PACK];
};
#define NCK_AUX_RING 256

/* ---- spindle-synchronised motion (sync.c, the position loop) -----------------
 * G33, G76's passes and G33.1 do not go through the planner: their position
 * along the path is pitch x the spindle's turns since its index, which only
 * the position loop knows. The job thread gathers a run of consecutive
 * synchronised lines (one START_SPEED_FEED_SYNCH .. STOP stretch; the pitch
 * may change between lines, as at G76's tapers) and sends it on the sync
 * ring; an NCK_AUX_SYNC action after an AUX stop at the run's start makes
 * the loop run it, and the planner goes on from the run's end. */
#define NCK_SYNC_LINES 8
#define NCK_SYNC_RING 16
struct nck_sync_run {
    int n;
    int tap;                   /* G33.1: in, spindle reversed, back out */
    double start[NCP_AXES];
    struct nck_sync_line {
        double end[NCP_AXES];
        double len, pitch;     /* mm, mm per turn along the line */
        uint32_t line;
    } l[NCK_SYNC_LINES];
};

#endif
