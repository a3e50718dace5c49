/* Cutter radius compensation (G40, G41, G42, G41.1, G42.1) as rs274 does it.
 *
 * rs274 compensates with a one-move delay: a compensated move sits in a queue
 * until the next move decides its real end point (inside corners pull it back
 * to the intersection of the two offset paths, outside corners add an arc),
 * and some non-motion calls issued meanwhile wait in the same queue so they
 * keep their place after it. This module keeps that queue, so the analyzer
 * core hands it every move and canonical call while compensation is engaged
 * and it passes them on, finished, through a sink. Geometry per move is a few
 * atan2/hypot calls (src/geom/comp.cpp).
 *
 * Plane coordinates: XY plane (G17) first=x second=y axis=z; XZ plane (G18)
 * first=z second=x axis=y, as rs274 and ARC_FEED order them. */
#ifndef NCP_ANALYZER_CUTCOMP_H
#define NCP_ANALYZER_CUTCOMP_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/canon.h"
#include "ncpar/diag.h"

#define NCP_COMP_QUEUE_MAX 64     /* queued calls between two moves */
#define NCP_COMP_TEXT_POOL 4096   /* comment text held by queued calls */

/* Where finished calls go: the analyzer core appends op (and text, len bytes,
 * not NUL-terminated, for COMMENT) to the slot it is filling. Returns NCP_OK
 * or an error code (which aborts the comp call with that code). */
struct ncp_comp_sink {
    void *ctx;
    int (*emit)(void *ctx, const struct ncp_canon *op, const char *text, size_t len);
};

enum ncp_comp_kind { NCP_CQ_FEED, NCP_CQ_TRAVERSE, NCP_CQ_ARC, NCP_CQ_OTHER };

struct ncp_comp_entry {
    uint8_t kind;             /* enum ncp_comp_kind */
    int turn;                 /* arcs */
    double p[3];              /* end: first, second, axis */
    double centre[2];         /* arcs */
    double abc[3];
    double dir[2];            /* straight: direction rs274 checks reversal against */
    double original_turns;    /* arcs: programmed sweep, 0 = never checked */
    struct ncp_canon op;      /* NCP_CQ_OTHER; text_off into the comp text pool */
};

struct ncp_comp_cfg {
    double spiral_abs_tol_inch, spiral_abs_tol_mm; /* [RS274NGC] CENTER_ARC_RADIUS_TOLERANCE_*, 0 = default */
};

struct ncp_cutcomp {
    struct ncp_comp_cfg cfg;
    int side;                 /* 0 off, 1 left, 2 right */
    double radius;            /* >= 0; 0 = on but nothing to offset */
    int orientation;          /* lathe tool orientation (G18), 0/9 = mill */
    int plane;                /* 0 XY, 2 XZ at G41/G42 */
    int inches;
    int firstmove;
    int arc_not_allowed;      /* the move after G40 must be straight */
    double prog[3];           /* programmed point (plane coords) */
    double cur[3];            /* compensated point (plane coords) */
    double endpoint[2];       /* start of the queued move(s), for gouge checks */
    int endpoint_valid;
    struct ncp_canon inv_feed;/* G93 arc rate waiting for its (compensated) arc */
    int inv_pending;
    unsigned n;
    size_t text_used;
    struct ncp_comp_entry q[NCP_COMP_QUEUE_MAX];
    char text[NCP_COMP_TEXT_POOL];
};

/* G41/G42/G41.1/G42.1 block. */
struct ncp_comp_on_req {
    int gcode;                /* 410, 411, 420, 421 */
    int plane;                /* 0 XY, 1 YZ, 2 XZ */
    int inches;               /* program units */
    int has_d, has_l;
    double d;                 /* D word (tool number, or diameter for G4x.1) */
    int l;                    /* L word: lathe orientation for G4x.1 */
    uint32_t line;
    /* G41/G42 tool lookup: toolno -1 = the tool in the spindle (no D word).
     * Fill diameter in program units and orientation; return 0, or -1 when the
     * tool is not in the table. */
    int (*tool)(void *ctx, int toolno, double *diameter, int *orientation);
    void *tool_ctx;
};

/* A programmed G0/G1/G2/G3 while compensation is engaged. */
/* G33/G33.1/G76: rs274's compensation knows only G0 and G1. It fails them where it
 * picks the call by the code (the entry move, a move without motion in the
 * plane, a convex corner's arc) and makes them plain feeds everywhere else. */
#define NCP_COMP_SYNCED 33

struct ncp_comp_move {
    int motion;               /* 0 G0, 1 G1, 2 G2, 3 G3, NCP_COMP_SYNCED */
    double start[3];          /* programmed start, plane coords */
    double end[3];            /* programmed end, plane coords */
    double abc[3];            /* end a b c */
    int radius_form;          /* arcs: 1 R word, 0 centre */
    double centre[2];         /* arcs, centre form: absolute centre, plane coords */
    double r;                 /* arcs, R form: signed R word */
    int turns;                /* arcs: P word, 0/1 = one */
    int inches;
    int g53;                  /* G53 in the block: an error with comp */
    uint32_t line;
};

void ncp_cutcomp_init(struct ncp_cutcomp *c, const struct ncp_comp_cfg *cfg);

/* Program start / M2 / M30 reset: comp off, queue dropped (flush first). */
void ncp_cutcomp_reset(struct ncp_cutcomp *c);

/* G41... Checks plane, "already on", D/L words, emits rs274's COMMENT. */
int ncp_cutcomp_on(struct ncp_cutcomp *c, const struct ncp_comp_on_req *req,
                   const struct ncp_comp_sink *sink, struct ncp_diag *d);

/* G40: COMMENT, then the queue drains with the last move ending where it was. */
int ncp_cutcomp_off(struct ncp_cutcomp *c, const struct ncp_comp_sink *sink,
                    struct ncp_diag *d, uint32_t line);

/* M0 M1 M2 M30 M60 (rs274's convert_stop): drain the queue, comp stays on. */
int ncp_cutcomp_flush(struct ncp_cutcomp *c, const struct ncp_comp_sink *sink,
                      struct ncp_diag *d, uint32_t line);

/* G20/G21 that changes units (k = 25.4 or 1/25.4): radius, points and any
 * queued moves follow, as rs274's qc_scale does. */
void ncp_cutcomp_scale(struct ncp_cutcomp *c, double k, int inches);

/* Side != off and radius > 0: moves must go through ncp_cutcomp_move. */
int ncp_cutcomp_engaged(const struct ncp_cutcomp *c);

/* A call outside compensation left the tool at machine-plane X Y (G5.3:
 * rs274 moves its current point, not the programmed one, to the NURBS end). */
void ncp_cutcomp_moved_to(struct ncp_cutcomp *c, double x, double y);

/* Before every G0/G1/G2/G3 (engaged or not): the arc-after-G40 rule. */
int ncp_cutcomp_check_motion(struct ncp_cutcomp *c, int is_arc, struct ncp_diag *d,
                             uint32_t line);

/* A compensated move: queues it and emits whatever it finalises. */
int ncp_cutcomp_move(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                     const struct ncp_comp_sink *sink, struct ncp_diag *d);

/* Any other canonical call (while comp is engaged, or always: it is a plain
 * pass-through when the queue is empty). Calls rs274 queues wait behind the
 * pending move; the rest are emitted at once. A SET_FEED_RATE flagged
 * NCP_FEED_F_INVERSE_ARC (G93 arc, see canon.h) offered while comp is engaged
 * waits for the next ncp_cutcomp_move, which fills in the arc's rate. */
int ncp_cutcomp_other(struct ncp_cutcomp *c, const struct ncp_canon *op, const char *text,
                      size_t len, const struct ncp_comp_sink *sink, struct ncp_diag *d,
                      uint32_t line);

#endif
