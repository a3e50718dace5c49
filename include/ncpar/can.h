/* A small CANopen master over raw SocketCAN for CiA 402 drives: bus access,
 * NMT, SYNC, expedited SDO, PDO 1 encode/decode, EMCY and heartbeat decoding,
 * the CiA 402 state machine. No CANopen library: every frame is built here. */
#ifndef NCPAR_CAN_H
#define NCPAR_CAN_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "ncpar/diag.h"

/* Function codes of the pre-defined connection set (add the node id). */
#define NCP_COB_NMT       0x000u
#define NCP_COB_SYNC      0x080u
#define NCP_COB_EMCY      0x080u
#define NCP_COB_TPDO1     0x180u
#define NCP_COB_RPDO1     0x200u
#define NCP_COB_TPDO2     0x280u /* digital inputs 0x60FD, when mapped */
#define NCP_COB_SDO_TX    0x580u /* server (drive) -> client (master) */
#define NCP_COB_SDO_RX    0x600u /* client -> server */
#define NCP_COB_HEARTBEAT 0x700u

#define NCP_CAN_NODE_MAX 127

struct ncp_can_frame {
    uint32_t id;   /* 11-bit identifier */
    uint8_t len;   /* 0..8 */
    uint8_t rtr;
    uint8_t data[8];
};

struct ncp_can_bus {
    int fd;
    char ifname[16];
};

/* ---- raw bus --------------------------------------------------------- */
int ncp_can_open(struct ncp_can_bus *bus, const char *ifname, struct ncp_diag *d);
void ncp_can_close(struct ncp_can_bus *bus);
/* Kernel receive filter: only these exact identifiers pass (n == 0: all). */
int ncp_can_filter(struct ncp_can_bus *bus, const uint32_t *ids, size_t n,
                   struct ncp_diag *d);
int ncp_can_send(struct ncp_can_bus *bus, const struct ncp_can_frame *f,
                 struct ncp_diag *d);
/* 1: frame read; 0: nothing within timeout_ms; -1: error (in d). */
int ncp_can_recv(struct ncp_can_bus *bus, struct ncp_can_frame *f, int timeout_ms,
                 struct ncp_diag *d);
/* Real-time variants: one non-blocking send()/recv() (MSG_DONTWAIT), no
 * formatting. try_send: 0 sent, 1 queue full (try next period), -1 error in
 * errno. try_recv: 1 frame, 0 nothing waiting, -1 error in errno. */
int ncp_can_try_send(struct ncp_can_bus *bus, const struct ncp_can_frame *f);
int ncp_can_try_recv(struct ncp_can_bus *bus, struct ncp_can_frame *f);

/* ---- NMT, SYNC ------------------------------------------------------- */
enum ncp_nmt_cmd {
    NCP_NMT_START = 0x01,
    NCP_NMT_STOP = 0x02,
    NCP_NMT_PRE_OPERATIONAL = 0x80,
    NCP_NMT_RESET_NODE = 0x81,
    NCP_NMT_RESET_COMM = 0x82,
};
/* node 0 addresses every node. */
void ncp_nmt_frame(struct ncp_can_frame *f, enum ncp_nmt_cmd cmd, uint8_t node);
void ncp_sync_frame(struct ncp_can_frame *f);

/* ---- heartbeat ------------------------------------------------------- */
enum ncp_nmt_state {
    NCP_NMT_BOOTUP = 0x00,
    NCP_NMT_STOPPED = 0x04,
    NCP_NMT_OPERATIONAL = 0x05,
    NCP_NMT_PREOP = 0x7F,
};
void ncp_heartbeat_frame(struct ncp_can_frame *f, uint8_t node, enum ncp_nmt_state s);
const char *ncp_nmt_state_name(unsigned state);

/* ---- expedited SDO --------------------------------------------------- */
/* Frames of the protocol, for the client here and for simulated servers. */
void ncp_sdo_upload_req(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                        uint8_t sub);
/* size 1, 2 or 4 bytes. */
void ncp_sdo_download_req(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                          uint8_t sub, uint32_t value, unsigned size);
void ncp_sdo_upload_resp(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                         uint8_t sub, uint32_t value, unsigned size);
void ncp_sdo_download_resp(struct ncp_can_frame *f, uint8_t node, uint16_t index,
                           uint8_t sub);
void ncp_sdo_abort_frame(struct ncp_can_frame *f, uint32_t cob, uint16_t index,
                         uint8_t sub, uint32_t code);
/* Text of an SDO abort code (CiA 301), "unknown abort code" if not listed. */
const char *ncp_sdo_abort_text(uint32_t code);

/* Blocking client calls. Frames other than the awaited answer are skipped, so
 * give the SDO its own bus (filtered to 0x580 + node) while PDOs run. On error
 * d->msg names node, object and cause ("node 2: SDO write 0x6060:00: ..."),
 * *abort (may be NULL) gets the abort code or 0. */
int ncp_sdo_read(struct ncp_can_bus *bus, uint8_t node, uint16_t index, uint8_t sub,
                 uint32_t *value, int timeout_ms, uint32_t *abort, struct ncp_diag *d);
int ncp_sdo_write(struct ncp_can_bus *bus, uint8_t node, uint16_t index, uint8_t sub,
                  uint32_t value, unsigned size, int timeout_ms, uint32_t *abort,
                  struct ncp_diag *d);

/* ---- PDO 1 of a CSP drive: controlword + target, statusword + actual -- */
void ncp_rpdo1_frame(struct ncp_can_frame *f, uint8_t node, uint16_t controlword,
                     int32_t target);
int ncp_rpdo1_decode(const struct ncp_can_frame *f, uint16_t *controlword,
                     int32_t *target);
void ncp_tpdo1_frame(struct ncp_can_frame *f, uint8_t node, uint16_t statusword,
                     int32_t actual);
int ncp_tpdo1_decode(const struct ncp_can_frame *f, uint16_t *statusword,
                     int32_t *actual);

/* ---- EMCY ------------------------------------------------------------ */
struct ncp_emcy {
    uint16_t code;     /* error code, 0x0000 = error reset */
    uint8_t reg;       /* error register 0x1001 */
    uint8_t vendor[5];
};
void ncp_emcy_frame(struct ncp_can_frame *f, uint8_t node, const struct ncp_emcy *e);
int ncp_emcy_decode(const struct ncp_can_frame *f, struct ncp_emcy *e);
/* The meaning of an EMCY error code: the codes CiA 402 servos commonly
 * send, the rest by their CiA 301 class ("monitoring error"). */
const char *ncp_emcy_code_text(uint16_t code);
/* "0x8611 following error; register 0x21: generic, device profile" */
void ncp_emcy_describe(const struct ncp_emcy *e, char *buf, size_t len);

/* ---- CiA 402 device control ------------------------------------------ */
enum ncp_cia402_state {
    NCP_402_NOT_READY,
    NCP_402_SWITCH_ON_DISABLED,
    NCP_402_READY_TO_SWITCH_ON,
    NCP_402_SWITCHED_ON,
    NCP_402_OPERATION_ENABLED,
    NCP_402_QUICK_STOP_ACTIVE,
    NCP_402_FAULT_REACTION_ACTIVE,
    NCP_402_FAULT,
};
#define NCP_402_CW_SHUTDOWN     0x0006u
#define NCP_402_CW_SWITCH_ON    0x0007u
#define NCP_402_CW_ENABLE       0x000Fu
#define NCP_402_CW_DISABLE      0x0000u
#define NCP_402_CW_QUICK_STOP   0x0002u
#define NCP_402_CW_FAULT_RESET  0x0080u

enum ncp_cia402_state ncp_cia402_state(uint16_t statusword);
const char *ncp_cia402_state_name(enum ncp_cia402_state s);
/* Controlword for one step towards Operation enabled. prev_cw is the last one
 * sent: fault reset acts on a rising edge of bit 7, so it alternates. */
uint16_t ncp_cia402_step(enum ncp_cia402_state s, uint16_t prev_cw);
/* Statusword a drive in state s reports (for simulated drives). */
uint16_t ncp_cia402_statusword(enum ncp_cia402_state s);
/* Next state of a drive in state s receiving controlword cw. */
enum ncp_cia402_state ncp_cia402_apply(enum ncp_cia402_state s, uint16_t cw,
                                       uint16_t prev_cw);
/* Statusword bit 10: in Quick stop active, the drive has come to rest. */
#define NCP_402_SW_TARGET_REACHED 0x0400u
/* TPDOs in a row with the same actual position that count as at rest for
 * a drive that does not set bit 10 in Quick stop active. */
#define NCP_402_STILL_TPDOS 3
/* An E-stop from the seat, for one drive: at rest after its quick stop
 * (bit 10, or still for NCP_402_STILL_TPDOS TPDOs)? */
int ncp_cia402_at_rest(uint16_t statusword, int still_tpdos);
/* The controlword of a drive being E-stopped: Quick Stop while it is
 * enabled or still braking, Disable Voltage once at rest, and at once in
 * any other state (Fault included: a reset is the operator's). */
uint16_t ncp_cia402_estop_cw(uint16_t statusword, int still_tpdos);

/* ---- what the master knows of each drive --------------------------- */
struct ncp_co_node {
    uint8_t id;
    uint16_t statusword;
    int32_t actual;
    uint32_t tpdos;       /* TPDO1 frames received */
    int64_t last_hb_ms;   /* -1: no heartbeat yet */
    uint8_t hb_state;     /* enum ncp_nmt_state */
    uint32_t emcys;       /* EMCY frames received; the last one in emcy */
    struct ncp_emcy emcy;
    uint32_t din;         /* digital inputs 0x60FD from TPDO2 (bit 2: home switch) */
    uint32_t dins;        /* TPDO2 frames received */
};
enum ncp_co_event { NCP_CO_NONE, NCP_CO_TPDO, NCP_CO_HEARTBEAT, NCP_CO_EMCY, NCP_CO_DIN };
/* 0x60FD bit 2 (CiA 402): the home switch. */
#define NCP_402_DIN_HOME_SWITCH 0x4u

void ncp_co_node_init(struct ncp_co_node *node, uint8_t id);
/* The COB-IDs a master listens to for these nodes (5 per node); returns count. */
size_t ncp_co_filter_ids(const struct ncp_co_node *nodes, size_t n, uint32_t *ids,
                         size_t max);
/* Updates the node the frame comes from; returns what the frame was. */
enum ncp_co_event ncp_co_track(struct ncp_co_node *nodes, size_t n,
                               const struct ncp_can_frame *f, int64_t now_ms);
/* NCP_OK while the node's last heartbeat is younger than timeout_ms (counted
 * from since_ms when none came yet); else the loss, described in d. */
int ncp_co_check_heartbeat(const struct ncp_co_node *node, int64_t now_ms,
                           int64_t since_ms, int timeout_ms, struct ncp_diag *d);

/* ---- the master of a set of CSP drives ------------------------------ */
#define NCP_CO_MAX_NODES 9 /* one per axis, X Y Z A B C U V W */

/* 0x60C2 interpolation time period: value * 10^index s. Picks the coarsest
 * exact unit for period_us; -1 when none fits a byte. */
int ncp_co_interp_period(long period_us, uint8_t *value, int8_t *index);

struct ncp_co_master_cfg {
    long period_us;       /* SYNC period = servo period */
    int sdo_timeout_ms;
    int hb_period_ms;     /* heartbeat producer time written to 0x1017 */
    int hb_timeout_ms;    /* a drive silent this long is lost */
    /* The drives guard the master (written at start-up when master_node > 0):
     * its own heartbeat goes out every hb_period_ms as node master_node; a
     * drive that misses it for hb_consumer_ms (0x1016:01), or RPDO1 for
     * rpdo_timeout_ms (0x1400:05, 0 = off), reacts as abort_option (0x6007)
     * and, for a fault, fault_reaction (0x605E) say. */
    uint8_t master_node;
    int hb_consumer_ms;
    int rpdo_timeout_ms;
    int abort_option;
    int fault_reaction;
    /* TPDO2 = digital inputs 0x60FD at every SYNC (a homing search reads
     * the home switch there); 0: not mapped */
    int map_din;
};

enum ncp_co_fault_kind {
    NCP_CO_FAULT_NONE,
    NCP_CO_FAULT_EMCY,      /* an EMCY frame */
    NCP_CO_FAULT_HEARTBEAT, /* no heartbeat within the timeout */
    NCP_CO_FAULT_NMT,       /* heartbeat says the node left Operational */
    NCP_CO_FAULT_STATE,     /* statusword left Operation enabled */
    NCP_CO_FAULT_BUS,       /* the socket refused frames */
    NCP_CO_FAULT_START,     /* start-up (SDO, state machine): text says what */
    NCP_CO_FAULT_HOMING,    /* the drive's own homing failed: home_why says how */
};
enum ncp_co_home_why { NCP_CH_WHY_ERROR, NCP_CH_WHY_TIMEOUT, NCP_CH_WHY_SDO };

/* What went wrong, recorded on the real-time path as plain values; turned
 * into text afterwards by ncp_co_fault_describe. */
struct ncp_co_fault {
    enum ncp_co_fault_kind kind;
    uint8_t node;
    struct ncp_emcy emcy;         /* EMCY */
    uint16_t statusword;          /* STATE */
    int32_t error_code;           /* STATE: 0x603F read after the stop, -1 unknown */
    int64_t hb_age_ms;            /* HEARTBEAT: -1 = none received at all */
    int hb_timeout_ms;
    uint8_t hb_state;             /* HEARTBEAT, NMT: the last NMT state reported */
    uint32_t cob;                 /* BUS: the frame that could not go out */
    int err;                      /* BUS: errno, 0 = queue full for too long */
    char text[NCP_DIAG_MSG_MAX];  /* START; HOMING with SDO: the failed exchange */
    int home_why;                 /* HOMING: enum ncp_co_home_why */
    int home_method;              /* HOMING: 0x6098 */
    long home_ms;                 /* HOMING: how long the drive homed */
};
/* ---- the drive's own homing mode (CiA 402 homing, dhome.c) ----------- */
#define NCP_402_MODE_HOMING 6
#define NCP_402_MODE_CSP 8
#define NCP_402_CW_HOMING_START 0x0010u    /* controlword bit 4 in homing mode */
#define NCP_402_SW_HOMING_ATTAINED 0x1000u /* statusword bit 12 */
#define NCP_402_SW_HOMING_ERROR 0x2000u    /* statusword bit 13 */
/* A drive in homing mode reports its last homing (bits 10, 12, 13) until
 * a new one starts, and TPDOs answering SYNCs from before the start edge
 * may still come in after it. So the end counts once the drive has shown
 * this homing under way (bit 10 clear), or, for one that ends at once
 * (method 35), this many TPDOs after the edge. */
#define NCP_CO_HOME_SETTLE_TPDOS 10

/* Where a drive's homing stands. IDLE follows the NCK's targets (CSP);
 * TO_HOMING and TO_CSP wait for the SDO worker to switch the mode; HOMING
 * has bit 4 up and watches the statusword; HOMED holds the drive at its
 * actual position until the NCK has taken it (ncp_co_home_poll). */
enum ncp_co_home_phase { NCP_CH_IDLE, NCP_CH_TO_HOMING, NCP_CH_HOMING, NCP_CH_TO_CSP,
                         NCP_CH_HOMED, NCP_CH_FAILED, NCP_CH_ABORTING };

/* The homing mode's parameters of one drive (before the loop). */
struct ncp_co_home_cfg {
    int on;                 /* the drive homes itself ([AXIS_L] HOME_METHOD = drive:N) */
    int method;             /* 0x6098, -128..127 */
    uint32_t search, latch; /* 0x6099:01, :02, counts/s; 0: the drive's own */
    uint32_t acc;           /* 0x609A, counts/s^2; 0: the drive's own */
    int32_t offset;         /* 0x607C, counts: the drive's position at its home */
    long timeout_periods;   /* servo periods the homing may take */
};

struct ncp_co_home {
    struct ncp_co_home_cfg cfg;
    int phase;              /* enum ncp_co_home_phase: the loop's */
    long periods;           /* in the phase */
    uint32_t tpdos_at;      /* the node's TPDO count when bit 4 went up */
    int under_way;          /* a TPDO since showed bit 10 clear */
    _Atomic unsigned phase_sw; /* the statusword that said homing attained (0 after a
                               failure or abort), for the worker's log */
    /* The loop asks the SDO worker for a mode of operation (want) by
     * counting ask up; the worker answers with done = the ask it served,
     * failed and why (written before done) when the exchange failed. */
    _Atomic uint32_t ask, done;
    _Atomic int want, failed;
    char why[NCP_DIAG_MSG_MAX];
};

/* One SDO download of a mode switch. */
struct ncp_co_sdo_step { uint16_t index; uint8_t sub; uint32_t value; unsigned size; };
/* The downloads that put a drive in mode (6: offset, method, speeds and
 * acceleration given, then 0x6060; 8: 0x6060 alone); the count. */
size_t ncp_co_home_sdo_steps(const struct ncp_co_home_cfg *c, int mode,
                             struct ncp_co_sdo_step *out, size_t max);

/* "node 5: EMCY (0x085): error code 0x8611 following error; ..." */
void ncp_co_fault_describe(const struct ncp_co_fault *f, const char *ifname, char *buf,
                           size_t len);

struct ncp_co_master {
    struct ncp_can_bus bus;
    struct ncp_co_node node[NCP_CO_MAX_NODES];
    uint16_t cw[NCP_CO_MAX_NODES];      /* controlword sent in RPDO1 */
    int32_t target[NCP_CO_MAX_NODES];   /* target position sent in RPDO1, counts */
    uint8_t enabled[NCP_CO_MAX_NODES];  /* reached Operation enabled */
    /* quick stop deceleration (0x6085, counts/s^2) a guarding drive brakes
     * with on its own: the axis's acceleration limit; 0 = the drive's own */
    uint32_t quick_stop_dec[NCP_CO_MAX_NODES];
    size_t n;
    struct ncp_co_master_cfg cfg;
    FILE *log;                          /* start-up progress, or NULL */
    int64_t started_ms;                 /* NMT start: heartbeats counted from here */
    long cycle;                         /* SYNCs sent */
    int64_t next_hb_ms;                 /* the master's next own heartbeat */
    unsigned tx_full;                   /* consecutive periods with a full queue */
    struct ncp_co_fault fault;
    /* The seat's E-stop and reset (cnc-run serve): RUN follows the targets;
     * ESTOP brakes every drive (Quick Stop, then Disable Voltage at rest);
     * ENABLING walks each back to Operation enabled holding its actual
     * position. still[]/seen[]: TPDOs in a row with an unchanged actual. */
    int mode;                           /* enum ncp_co_mode */
    uint8_t still[NCP_CO_MAX_NODES];
    uint32_t seen[NCP_CO_MAX_NODES];    /* node tpdos at the last look */
    int32_t last_act[NCP_CO_MAX_NODES];
    long mode_cycles;                   /* periods since the mode began */
    /* the drives' own homing (dhome.c) */
    struct ncp_co_home home[NCP_CO_MAX_NODES];
    /* blocking cycles call this for every TPDO taken in (tests judge them) */
    void (*on_tpdo)(void *ctx, size_t i);
    void *on_tpdo_ctx;
};

/* Opens ifname with receive filters for these nodes' SDO, TPDO1, EMCY and
 * heartbeat identifiers. */
int ncp_co_master_open(struct ncp_co_master *m, const char *ifname, const uint8_t *nodes,
                       size_t n, const struct ncp_co_master_cfg *cfg, struct ncp_diag *d);
void ncp_co_master_close(struct ncp_co_master *m);

/* ---- start-up and stop: blocking, never on the real-time thread ------- */
/* SDO configuration of node i: device type, CSP mode (confirmed by 0x6061),
 * interpolation period, PDO 1 mapping, heartbeat producer. */
int ncp_co_master_configure(struct ncp_co_master *m, size_t i, struct ncp_diag *d);
/* Every node configured, NMT start, then the CiA 402 walk to Operation
 * enabled (fault reset on the way). targets = actual positions after it. On
 * failure m->fault.kind != NONE and d->msg names node, object and cause. */
int ncp_co_master_startup(struct ncp_co_master *m, struct ncp_diag *d);
int ncp_co_master_enable(struct ncp_co_master *m, struct ncp_diag *d);
/* One period in blocking style: take in what arrived, RPDOs + SYNC, wait for
 * every node's TPDO of this SYNC (period + 100 ms at most: a missing one is
 * not fatal), check for faults, sleep out the period. */
int ncp_co_master_cycle(struct ncp_co_master *m, struct ncp_diag *d);
/* Controlled stop: every drive holds for a few periods (after a fault at
 * its actual position, else at its last target), then shutdown (0x06) and
 * NMT pre-operational. After a STATE fault it reads
 * the drive's error code 0x603F into m->fault. */
void ncp_co_master_stop(struct ncp_co_master *m);

/* ---- real-time path: no allocation, no locks, no blocking ------------ */
/* Takes in at most max waiting frames. -1 (m->fault set) on an EMCY. */
int ncp_co_master_poll(struct ncp_co_master *m, int64_t now_ms, int max);
/* Heartbeats and device states of the enabled drives; -1 with m->fault. */
int ncp_co_master_check(struct ncp_co_master *m, int64_t now_ms);
/* RPDO1 of every node, then SYNC. A full transmit queue skips the rest of
 * the period's frames, SYNC included (the drives take their new targets at
 * the next SYNC); -1 with m->fault after 50 such periods in a row, or at
 * once on a socket error. */
int ncp_co_master_send(struct ncp_co_master *m);
int64_t ncp_co_now_ms(void);

/* ---- the seat: E-stop and reset of the drives (real-time, seat.c) ---- */
enum ncp_co_mode { NCP_CO_RUN, NCP_CO_ESTOP, NCP_CO_ENABLING };
/* Periods a reset may take to bring every drive to Operation enabled. */
#define NCP_CO_ENABLE_PERIODS 400
/* on = 0: E-stop every drive; 1 after an E-stop: walk them back to
 * Operation enabled (fault reset where in Fault), the fault and EMCY codes
 * forgotten (1 while running: nothing). */
void ncp_co_master_seat(struct ncp_co_master *m, int on);
/* Outside RUN, one period's controlwords, and targets at the actual
 * positions. ENABLING turns into RUN once every drive is enabled (then 0);
 * 1 while the mode holds the drives; -1 with a STATE fault when a reset
 * found a drive that would not enable within NCP_CO_ENABLE_PERIODS. */
int ncp_co_master_seat_step(struct ncp_co_master *m);

/* ---- the drive's own homing (dhome.c) -------------------------------- */
/* Real-time. start: node i (configured, IDLE, in RUN) begins homing; 0,
 * or -1 when it cannot. abort: an operator's stop: bit 4 down, back to CSP.
 * poll, for the NCK: 1 under way, 0 homed (the drive's counts start from
 * its home now; IDLE from here on, the NCK's targets followed again), -1
 * failed or aborted (IDLE or FAILED). */
int ncp_co_home_start(struct ncp_co_master *m, size_t i);
void ncp_co_home_abort(struct ncp_co_master *m, size_t i);
int ncp_co_home_poll(struct ncp_co_master *m, size_t i);
/* The seat's E-stop or reset (seat.c): every drive's homing ends, the
 * drive asked back to CSP where it was in homing mode. */
void ncp_co_home_drop(struct ncp_co_master *m);
/* Real-time, every RUN period after the poll: node i's controlword and,
 * while it homes, its target (the actual position). 1 while the homing
 * owns the node's target, 0 when idle, -1 with a HOMING fault in m->fault
 * (a homing error, the timeout, a failed mode switch). */
int ncp_co_home_step(struct ncp_co_master *m, size_t i);
/* Not real-time (the SDO worker): serves node i's pending mode switch on
 * bus (its own socket, filtered to the SDO answers): 1 served, 0 none. */
int ncp_co_home_serve(struct ncp_co_master *m, struct ncp_can_bus *bus, size_t i);

#endif
