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
    int heartbeat_on;
    /* servo plant (o.config): one axis of the sim backend's machine */
    int servo;
    struct ncp_machine_cfg cfg;
    struct ncp_sim sim;
    int32_t prev_target;  /* target of the previous SYNC: this period's command */
};

/* Loads o.config for the servo plant; -1 with a message on stderr. */
int drive_servo_load(struct drive *dv);
/* Entering Operation enabled: the plant starts where the drive stands. */
void drive_servo_enable(struct drive *dv);
/* One SYNC of the plant; returns the actual position (counts) at the SYNC. */
int32_t drive_servo_step(struct drive *dv);

void drive_boot(struct drive *dv);
/* Handles one received frame; returns -1 on a bus error. */
int drive_on_frame(struct drive *dv, const struct ncp_can_frame *f);
int drive_send_heartbeat(struct drive *dv);

#endif
