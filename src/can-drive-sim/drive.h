/* State of one simulated CiA 402 drive and its fault-injection switches. */
#ifndef NCP_DRIVE_SIM_DRIVE_H
#define NCP_DRIVE_SIM_DRIVE_H

#include <stdint.h>

#include "ncpar/backend.h"
#include "ncpar/can.h"
#include "od.h"

struct drive_opts {
    uint8_t node;
    int fault_at_start;
    long fault_after;     /* SYNCs in Operation enabled, then Fault; <0 never */
    long emcy_after;      /* ... then EMCY + Fault */
    long hb_stop_after;   /* ... then no more heartbeats */
    int slow_sdo_ms;      /* delay before every SDO answer */
    int abort_index;      /* SDO access to it is aborted; <0 none */
    long drop_every;      /* drop every N-th TPDO; 0 never */
    int32_t max_step;     /* plant slew limit, counts per SYNC */
    int verbose;
    /* --config INI --axis X|Y|Z: the sim backend's servo plant of that axis
     * ([SIM] gains, COUNTS_PER_MM) instead of the slew limit */
    const char *config;
    int axis;             /* 0..2, -1 = none */
    long sync_loss_ms;    /* no SYNC this long while enabled: the drive stops; 0 never */
    /* the K of --fault-after, --emcy-after and --heartbeat-stop-after counts
     * SYNCs from the first target that differs from the one at enabling, so
     * a fault lands at a point of the program however long start-up took */
    int count_from_motion;
    /* --home-switch COUNTS: 0x60FD bit 2 while the actual position is at
     * or above it */
    int have_home_switch;
    int32_t home_switch;
    /* --index-pitch COUNTS: the encoder's index pulse at every multiple of
     * it (homing methods 3 and 4); 0 none */
    int32_t index_pitch;
    /* homing that fails, for the master's error paths: a homing error
     * (bit 13) this many ms into the first homing (0: never), as a fault
     * the operator then fixes; a search that never finds the switch, so
     * nothing is ever attained */
    long homing_error_ms;
    int homing_stall;
};

/* The drive's own homing mode (0x6060 = 6, homing.c). */
enum drive_home_stage { DH_IDLE, DH_SEEK, DH_LATCH, DH_INDEX, DH_BRAKE };
struct drive_homing {
    int mode6;            /* in homing mode (0x6061 = 6) */
    int stage;            /* enum drive_home_stage */
    int attained, error;  /* statusword bits 12 and 13 */
    int found;            /* home found: the brake ends in attained */
    int dir;              /* direction of the latch (and index) stage */
    double pos, v;        /* counts, counts per second */
    int32_t ref;          /* the drive's position minus the encoder's: homing sets it */
    double elapsed;       /* seconds of this homing, for --homing-error */
};

struct drive {
    struct drive_opts o;
    struct od od;
    struct ncp_can_bus bus;
    enum ncp_nmt_state nmt;
    enum ncp_cia402_state st;
    uint16_t cw, prev_cw;
    int32_t target, actual;
    long syncs_enabled, tpdos;
    long syncs_moving;    /* SYNCs since the target first moved, 0 before */
    int32_t enabled_at;   /* the target at enabling */
    int homing_error_given; /* --homing-error's one homing error is past */
    int heartbeat_on;
    /* servo plant (o.config): one axis of the sim backend's machine */
    int servo;
    struct ncp_machine_cfg cfg;
    struct ncp_sim sim;
    int32_t prev_target;  /* target of the previous SYNC: this period's command */
    /* Guarding the master (guard.c): when its heartbeat (0x1016), SYNC or
     * RPDO1 (0x1400:05) was last seen, on the drive's own clock, in ms; -1
     * before the first. */
    long long last_master_hb, last_sync, last_rpdo;
    uint16_t lost;        /* EMCY code of the loss being reacted to, 0 none */
    int32_t prev_actual;  /* actual at the SYNC before: the speed when the master is lost */
    double stop_vel;      /* counts per period while ramping down on its own */
    long long next_step;  /* the ramp's next step, ms */
    enum ncp_cia402_state after_stop; /* where the ramp ends */
    int halted;           /* a quick stop's ramp ended (statusword bit 10) */
    long long now_ms;     /* the drive's clock at the frame being handled */
    struct drive_homing home;
};

/* 0x60C2: value * 10^index s, the period the master runs SYNC at. */
double drive_period_s(struct drive *dv);
/* Loads o.config for the servo plant; -1 with a message on stderr. */
int drive_servo_load(struct drive *dv);
/* Entering Operation enabled: the plant starts where the drive stands. */
void drive_servo_enable(struct drive *dv);
/* One SYNC of the plant; returns the actual position (counts) at the SYNC. */
int32_t drive_servo_step(struct drive *dv);

void drive_boot(struct drive *dv);
/* Handles one received frame at now_ms (the drive's clock); -1 on a bus error. */
int drive_on_frame(struct drive *dv, const struct ncp_can_frame *f, long long now_ms);
/* Shared with guard.c, which stands on drive.c and is not called back. */
/* The master's node-ID the drive consumes the heartbeat of (0x1016:01), 0 none. */
unsigned drive_master_node(struct drive *dv);
void drive_set_state(struct drive *dv, enum ncp_cia402_state s);
int drive_send(struct drive *dv, const struct ncp_can_frame *f);
int drive_go_fault(struct drive *dv, uint16_t code, int with_emcy);
/* The statusword of the drive's state; in Quick stop active with bit 10
 * (target reached) once the ramp has ended. */
uint16_t drive_statusword(const struct drive *dv);
/* A ramp at 0x6085 on the drive's own clock (guard.c steps it): in state
 * during, then after. The master's Quick Stop (controlword 0x0002 in
 * Operation enabled) is one that stays in Quick stop active. */
int drive_start_ramp(struct drive *dv, enum ncp_cia402_state during,
                     enum ncp_cia402_state after, long long now_ms);

/* homing.c: the drive's own homing mode. Home switch pressed (0x60FD bit
 * 2), on the encoder's counts; the statusword bits of homing mode; bit 4 of
 * the controlword going up (start) or down (interrupt); one SYNC of it,
 * returning the actual position; 0x6060 written. */
int drive_home_switch(const struct drive *dv);
uint16_t drive_home_statusword(const struct drive *dv);
void drive_home_control(struct drive *dv, uint16_t cw, uint16_t prev_cw);
int32_t drive_home_step(struct drive *dv);
void drive_home_mode(struct drive *dv, uint32_t mode);
/* The homing under way ends where the axis stands, nothing attained. */
void drive_home_halt(struct drive *dv);

/* guard.c: the deadlines of the master's heartbeat, SYNC and RPDO1, and the
 * drive's own reaction (0x6007, 0x605E) when one passes: called whenever the
 * drive wakes; -1 on a bus error. */
int drive_guard_tick(struct drive *dv, long long now_ms);
/* How long the drive may sleep before the next deadline or ramp step, ms. */
int drive_guard_wait_ms(struct drive *dv, long long now_ms);
/* The CAN identifiers the drive listens to (its filter): n returned. */
size_t drive_listen_ids(struct drive *dv, uint32_t ids[6]);
int drive_send_heartbeat(struct drive *dv);
/* TPDO1: statusword and actual position, now. */
int drive_send_tpdo(struct drive *dv);

#endif
