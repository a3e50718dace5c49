/* The machine configuration: the machine INI (LinuxCNC style) read into
 * struct ncp_machine_cfg, section by section, with its defaults and the
 * checks across keys, and the table of every key the reader takes. Every
 * module that reads a setting includes this header, not the one of the
 * module that acts on it; the settings other modules own and parse
 * themselves (ncpar/inject.h, ncpar/sched.h, ncpar/rt.h's thread places,
 * ncpar/kins.h) are held here by value. */
#ifndef NCPAR_CONFIG_H
#define NCPAR_CONFIG_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/diag.h"
#include "ncpar/inject.h"
#include "ncpar/kins.h"
#include "ncpar/rt.h"
#include "ncpar/sched.h"

/* The machine's axes, in LinuxCNC's order X Y Z A B C U V W. A machine has
 * the ones its [TRAJ] COORDINATES names (ncp_machine_cfg.axis_mask); the
 * others are absent: they never move and the trace leaves them out. Lengths
 * of A B C are degrees (velocities deg/s, accelerations deg/s^2).
 * The joints (what the servos drive) come from the axes through the
 * machine's kinematics (ncpar/kins.h, [KINS]) in the position loop; with
 * trivial kinematics joints are axes. */
#define NCP_AXES 9
#define NCP_AXIS_LETTERS "XYZABCUVW"
#define NCP_AXIS_A 3
#define NCP_AXIS_U 6
#define NCP_AXIS_BIT(i) (1u << (i))
#define NCP_AXES_XYZ 0x7u
/* The canonical calls carry X Y Z A B C: U V W of a program never reach the
 * NCK (rs274's calls have no U V W either). */
#define NCP_CANON_AXES 6
static inline int ncp_axis_rotary(int i) { return i >= 3 && i < 6; }

enum ncp_profile { NCP_PROFILE_TRAPEZOID, NCP_PROFILE_SCURVE };

/* [PLANNER] NCK (the distributed-NCK paper): ADCBI plans acc/dec on the path with look-ahead
 * before interpolating (src/motion/planner.c); ADCAI interpolates at the
 * programmed feed and filters each axis afterwards (ncpar/adcai.h). */
enum ncp_nck_variant { NCP_NCK_ADCBI, NCP_NCK_ADCAI };
/* [LCM] CLOCK: the distributed mode's common time base (ax_status_t's
 * CLOCK_* constants) */
enum ncp_lcm_clock { NCP_LCM_CLOCK_MONOTONIC, NCP_LCM_CLOCK_PROBE, NCP_LCM_CLOCK_PTP };
/* [LCM] CLOCK's word for mode (as the INI spells it); a value out of range,
 * as a status from elsewhere may carry, reads as the default, monotonic. */
const char *ncp_lcm_clock_name(int mode);

struct ncp_axis_cfg {
    double min_limit, max_limit;  /* soft limits, mm */
    double max_vel, max_acc, max_jerk;
    double ferror;                /* following-error fault limit, mm */
    /* socketcan backend: the CiA 402 drive of this axis (0 = none) and its
     * position scaling, encoder counts per mm (0 = not set) */
    int node_id;
    double counts_per_mm;
    /* homing, LinuxCNC's keys (src/config/config_home.c, src/nck/homing.c):
     * HOME_SEARCH_VEL signed, 0 = no switch (the axis is homed where it
     * stands); HOME_LATCH_VEL signed (same sign: latch moving onto the
     * switch, opposite: moving off it); HOME_FINAL_VEL 0 = MAX_VELOCITY;
     * HOME_OFFSET the switch's position once homed; HOME where the axis
     * goes then. home_sequence: HOME_SEQUENCE (have_home_sequence 0: not
     * given); negative = the group's final moves start together. */
    double home, home_offset, home_search_vel, home_latch_vel, home_final_vel;
    int home_sequence, have_home_sequence, home_ignore_limits;
    /* HOME_METHOD = drive:N: the axis's CiA 402 drive homes itself with
     * homing method N (home_drive 0: the NCK homes it) */
    int home_drive, home_method;
    /* [SIM] HOME_SWITCH_<axis>: where the simulated switch is, in the
     * simulated machine's own coordinates (have_home_switch 0: at
     * HOME_OFFSET, as LinuxCNC's sim configs place it) */
    double home_switch;
    int have_home_switch;
    /* A B C: WRAPPED_ROTARY = 1, the axis turns without end: a move takes the
     * shorter way round to its target modulo 360 and the soft limits do not
     * apply */
    int wrapped;
};

/* What the position loop drives (backend.h): the simulated machine, CiA 402
 * drives over SocketCAN, or cnc-axis LLCs over LCM (the distributed mode). */
enum ncp_backend_kind { NCP_BACKEND_SIM, NCP_BACKEND_SOCKETCAN, NCP_BACKEND_LCM };

/* [CAN] */
struct ncp_can_cfg {
    char interface[16];           /* INTERFACE, e.g. can0 ("" = not set) */
    int heartbeat_period_ms;      /* HEARTBEAT_PERIOD_MS: drives' producer time (0x1017) */
    int heartbeat_timeout_ms;     /* HEARTBEAT_TIMEOUT_MS: later than this = lost */
    int sdo_timeout_ms;           /* SDO_TIMEOUT_MS: start-up SDO answer deadline */
    int master_node;              /* MASTER_NODE: our heartbeat's node-ID (127); 0: drives
                                     do not guard the master */
    int hb_consumer_ms;           /* HEARTBEAT_CONSUMER_MS: drives stop when our heartbeat
                                     is this late (0x1016) */
    int rpdo_timeout_ms;          /* RPDO_TIMEOUT_MS: ... or RPDO1 (0x1400:05), 0 off */
    int abort_option;             /* ABORT_CONNECTION_OPTION: 0x6007 (3: quick stop) */
    int fault_reaction;           /* FAULT_REACTION_OPTION: 0x605E (2: quick stop ramp) */
};


/* The machine functions around the axes (src/config/config_io.c): the
 * simulated spindle, the tool changer's position and the simulated inputs.
 * Every key is optional; the defaults are an ideal spindle (at any speed in
 * one servo period), no tool change move and pauses that resume at once. */
#define NCP_SPINDLE_TOP_RPM 1e6   /* the highest MAX_RPM, and the default */
#define NCP_DIO_MAX 64  /* digital inputs and outputs, P0..P63 */
#define NCP_AIO_MAX 16  /* analog inputs and outputs, E0..E15 */
struct ncp_io_cfg {
    double spindle_max_rpm;       /* [SPINDLE_0] MAX_RPM: S above it runs at it, said to the
                                     operator (absent or 0: NCP_SPINDLE_TOP_RPM) */
    double spindle_acc;           /* [SPINDLE_0] MAX_ACCELERATION, rpm/s (0: ideal) */
    double orient_rpm;            /* [SPINDLE_0] ORIENT_RPM: M19's top speed (60) */
    double at_speed_tol;          /* [SPINDLE_0] AT_SPEED_TOLERANCE: fraction of S (0.01) */
    double auto_resume_s;         /* [SIM] AUTO_RESUME_S: cnc-run run's pauses last this
                                     long (0); negative: until SIGUSR1 */
    uint64_t din;                 /* [SIM] DIGITAL_IN_<n> = 0|1: cnc-run run's inputs */
    double ain[NCP_AIO_MAX];      /* [SIM] ANALOG_IN_<n> */
    int have_tc_pos;              /* [EMCIO] TOOL_CHANGE_POSITION = X Y Z given */
    double tc_pos[3];             /* machine coordinates, mm */
    int quill_up;                 /* [EMCIO] TOOL_CHANGE_QUILL_UP: Z to machine 0 first */
    /* The simulated workpiece a G38.x probe touches (machine coordinates,
     * mm): the probe is in contact inside the box or below the plane. */
    int have_probe_box;           /* [SIM] PROBE_BOX = xmin ymin zmin xmax ymax zmax */
    double probe_box[6];
    int have_probe_plane;         /* [SIM] PROBE_PLANE_Z = z */
    double probe_plane_z;
};

/* [JOINT_n] (n: the place of the joint's letter in COORDINATES, from 0):
 * the limits of what a servo drives, checked after the inverse kinematics.
 * A joint without its section, or a key it leaves out, takes its axis's
 * value. Stored by axis index (joint i drives axis i's letter). */
struct ncp_joint_cfg {
    double min_limit, max_limit;  /* mm (deg for A B C) */
    double max_vel, max_acc;      /* mm/s, mm/s^2 */
    double ferror;                /* following-error fault limit */
};

struct ncp_machine_cfg {
    double servo_period;          /* s ([EMCMOT] SERVO_PERIOD is in ns) */
    double max_linear_vel;        /* [TRAJ] MAX_LINEAR_VELOCITY */
    double default_linear_acc;    /* [TRAJ] DEFAULT_LINEAR_ACCELERATION, 0 = axis limits */
    struct ncp_axis_cfg axis[NCP_AXES];
    /* [TRAJ] COORDINATES: the axes the machine has (NCP_AXIS_BIT), XYZ by default */
    unsigned axis_mask;
    int lookahead;                /* [PLANNER] LOOKAHEAD, segments */
    enum ncp_profile profile;     /* [PLANNER] PROFILE */
    enum ncp_nck_variant nck;     /* [PLANNER] NCK */
    int setpoint_ring;            /* [PLANNER] SETPOINT_RING, servo cycles buffered (1024) */
    /* [SIM]: PID of the simulated plant plus feed-forward (LinuxCNC pid naming):
     * u = KP e + KI int(e) + KD de/dt + FF1 v_cmd + FF2 a_cmd */
    double kp, ki, kd, ff1, ff2;
    /* where the simulated machine's joints stand when it starts: not an INI
     * key (0, the machine's zero); serve's estimate starts where its machine
     * stands */
    double sim_start[NCP_AXES];
    struct ncp_rt_place position, planner, interp; /* [RT] */
    struct ncp_sched_cfg sched;   /* [SCHED]: the soft-RT tasks' priorities, trace columns */
    /* [TRAJ] PLANNING_PERIOD (ns in the INI): the rough interpolator's period,
     * an integer multiple of servo_period; the position loop fine-interpolates
     * between its points. 0 = servo_period (no fine interpolation). */
    double planning_period;
    enum ncp_backend_kind backend; /* [EMCMOT] BACKEND, over which --backend goes */
    struct ncp_can_cfg can;
    /* [TRAJ] NO_FORCE_HOMING = 1: programs, MDI and jogs may run before the
     * axes are homed (LinuxCNC's key; 0, the default, refuses them) */
    int no_force_homing;
    double default_linear_vel;    /* [TRAJ] DEFAULT_LINEAR_VELOCITY: jog speed, mm/s */
    struct ncp_lcm_cfg {          /* [LCM]: cnc-run serve's messaging */
        char url[256];            /* URL ("" = $LCM_DEFAULT_URL or LCM's default) */
        char prefix[32];          /* CHANNEL_PREFIX, default NCP_ */
        double status_hz;         /* STATUS_HZ, default 50; 0: only at state changes
                                     and after each command */
        /* who may command the machine (ncpar/auth.h) */
        char key_file[512];       /* KEY_FILE ("": --key-file, else the user's
                                     ~/.config/ncpar/lcm.key) */
        char interface[16];       /* INTERFACE: the group joined there only (lo) */
        int status_needs_key;     /* STATUS_NEEDS_KEY: status and events encrypted (0) */
        int max_age_ms;           /* MAX_AGE_MS: the distributed NCK's messages
                                     sealed longer ago are dropped (2000) */
        /* the distributed mode (cnc-run run --backend lcm, cnc-axis) of the
           distributed-NCK paper */
        int dp;                   /* DP: distribution point 1..5 (5) */
        /* DP 1: the program and what it needs, absolute (not from the INI:
         * cnc-run run's PROG, --tool-table, --sub-path) */
        char program[256], tool_table[256], sub_path[256];
        int max_lost_periods;     /* MAX_LOST_PERIODS: statuses (HLC) or setpoints
                                     (LLC) missing in a row before a controlled stop (20) */
        int heartbeat_period_ms;  /* HEARTBEAT_PERIOD_MS (20) */
        int heartbeat_timeout_ms; /* HEARTBEAT_TIMEOUT_MS: a peer silent this long is lost (200) */
        int axis_wait_ms;         /* AXIS_WAIT_MS: how long the HLC waits for the axes'
                                     advertisements (5000) */
        double inject_loss;       /* INJECT_LOSS: fraction of received messages dropped (0) */
        int inject_delay_us;      /* INJECT_DELAY_US: every received message held back (0) */
        int inject_seed;          /* INJECT_SEED (1) */
        /* CLOCK: monotonic (one host: every clock is the HLC's), probe (each
         * LLC estimates the HLC's clock from probe round trips) or ptp
         * (CLOCK_REALTIME, kept common by ptp4l/phc2sys); monotonic */
        enum ncp_lcm_clock clock;
        int clock_tolerance_us;   /* CLOCK_TOLERANCE_US: under monotonic and ptp, an
                                     LLC whose probes find the clocks further apart
                                     stops (1000) */
    } lcm;
    struct ncp_http_cfg {         /* [HTTP]: cnc-run serve --http's panel */
        /* ALLOW_ORIGIN: pages of other origins that may use the panel, and
         * ALLOW_HOST: names besides its address and localhost it answers to;
         * space- or comma-separated lists, "" for none (both default) */
        char allow_origin[512], allow_host[512];
    } http;
    struct ncp_op_cfg {           /* what the operator sets, and its bounds */
        /* [RS274NGC] PARAMETER_FILE and [EMCIO] TOOL_TABLE, made absolute
         * from the INI's folder as LinuxCNC reads them ("": not given) */
        char parameter_file[512], tool_table[512];
        /* [DISPLAY] HISTORY_FILE: serve's job history, absolute ("": none);
         * history_given: the INI has the key (NONE turns the history off,
         * without it serve keeps one in the user's data folder) */
        char history_file[512];
        int history_given;
        /* [DISPLAY] MAX_FEED_OVERRIDE (1.0), MIN_SPINDLE_OVERRIDE (0.0) and
         * MAX_SPINDLE_OVERRIDE (2.0): ratios, 1.0 = 100 % */
        double max_feed_override, min_spindle_override, max_spindle_override;
    } op;
    struct ncp_io_cfg io;
    /* [INJECT] and [RT]'s miss keys: timing faults, setpoint policy, miss limits */
    struct ncp_inject_cfg inject;
    struct ncp_kins kins;         /* [KINS] KINEMATICS and the pivot offsets */
    struct ncp_joint_cfg joint[NCP_AXES];
    /* The interpreter's keys of a LinuxCNC INI ([RS274NGC], [DISPLAY]
     * PROGRAM_PREFIX). REMAP, SUBROUTINE_PATH and INI_VARS are the
     * interpreter's own: cnc-run reads them from the same file (rs274_ini.c);
     * the NCK needs only where the user M codes' programs are. Folders are
     * absolute here, relative ones taken from the INI's folder. */
    struct ncp_rs274_cfg {
        char program_prefix[512]; /* [DISPLAY] PROGRAM_PREFIX ("" none) */
        char user_m_path[1024];   /* [RS274NGC] USER_M_PATH, ':' between folders */
        /* both, in LinuxCNC's order of search for M100..M199: PROGRAM_PREFIX,
         * then USER_M_PATH's folders; "" none */
        char user_m_dirs[1540];
    } rs274;
};

void ncp_machine_cfg_default(struct ncp_machine_cfg *c);
/* Loads an INI over the defaults. On error d->msg names file, section and key,
 * d->line is the INI line. Returns NCP_OK or NCP_ERR_IO / NCP_ERR_SEMANTIC. */
int ncp_machine_cfg_load(struct ncp_machine_cfg *c, const char *path, struct ncp_diag *d);
/* config_io.c: the defaults of ncp_io_cfg, and one key of the sections it
 * reads ([SPINDLE_0], [EMCIO], [SIM]'s input and pause keys): 1 taken, 0
 * unknown key, -1 bad value (why says more), -2 not one of its sections. */
/* config_op.c: the defaults of ncp_op_cfg, and one key of its sections
 * ([RS274NGC], [DISPLAY], [EMCIO] TOOL_TABLE), a path made absolute from
 * ini_path's folder: 1 taken, 0 unknown, -1 bad value, -2 not its key. */
void ncp_op_cfg_default(struct ncp_op_cfg *op);
int ncp_op_cfg_key(struct ncp_op_cfg *op, const char *ini_path, const char *sec, const char *k,
                   const char *v, char *why, size_t len);
/* after the load: the overrides' bounds against each other */
int ncp_op_cfg_check(const struct ncp_op_cfg *op, char *why, size_t len);
void ncp_io_cfg_default(struct ncp_io_cfg *io);
int ncp_io_cfg_key(struct ncp_io_cfg *io, const char *sec, const char *k, const char *v,
                   char *why, size_t len);
/* config_rs274.c: one key of [RS274NGC] or [DISPLAY] (1 taken, 0 unknown,
 * -1 bad value, -2 not one of those sections); ini_path is the INI's, for
 * its relative folders. ncp_rs274_cfg_finish joins the folders once the
 * file is read. */
int ncp_rs274_cfg_key(struct ncp_rs274_cfg *r, const char *ini_path, const char *sec,
                      const char *k, const char *v, char *why, size_t len);
void ncp_rs274_cfg_finish(struct ncp_rs274_cfg *r);
/* config_home.c: one [AXIS_L] homing key (1 taken, 0 unknown, -1 bad
 * value), one [SIM] HOME_SWITCH_<L> key (same, -2 not such a key), and the
 * checks across an axis's homing keys once the file is read (0, or -1 with
 * why filled). */
int ncp_home_cfg_key(struct ncp_axis_cfg *a, const char *k, const char *v, char *why,
                     size_t len);
int ncp_home_switch_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                        size_t len);
int ncp_home_cfg_check(const struct ncp_machine_cfg *c, int axis, char *why, size_t len);
/* Servo periods per planning period (1 when planning_period is 0), or 0 when
 * planning_period is not a positive integer multiple of servo_period. */
int ncp_machine_cfg_ipo_ratio(const struct ncp_machine_cfg *c);
/* Every joint's limits from its axis's (the start of an INI load, and the
 * built-in machine). */
void ncp_machine_joints_from_axes(struct ncp_machine_cfg *c);
/* Does the machine have non-trivial kinematics? */
static inline int ncp_kins_active(const struct ncp_machine_cfg *c)
{
    return c->kins.type != NCP_KINS_TRIVIAL;
}

/* ---- the channels INI (config_cell.c) -------------------------------------
 * cnc-run serve --config CELL.ini: one [CHANNEL_n] section per NC channel
 * (n 0..NCP_CELL_MAX-1), naming its machine INI (CONFIG, relative to the
 * file's folder) and what drives that machine (BACKEND, and DP for lcm:
 * each left out takes the machine INI's [EMCMOT] BACKEND, [LCM] DP). The
 * machine's settings stay in the machine INIs: a file with [CHANNEL_n] and
 * any other section is refused, so that no key is read from the wrong one.
 * Its keys are rows of the table below like the machine INI's. */
#define NCP_CELL_MAX 16
#define NCP_CELL_PATH_MAX 4096
struct ncp_cell_channel {
    int num;                        /* n of [CHANNEL_n] */
    char config[NCP_CELL_PATH_MAX]; /* the machine INI, as a path from here */
    int backend;                    /* enum ncp_backend_kind, -1: the machine INI's */
    char interface[16];             /* socketcan:IFACE; "": the machine's [CAN] INTERFACE */
    int dp;                         /* 1..5, 0: the machine INI's [LCM] DP */
    /* where each was given in the channels INI (0: not given) */
    unsigned line, config_line, backend_line, dp_line;
};
struct ncp_cell {
    int n;
    struct ncp_cell_channel ch[NCP_CELL_MAX];   /* by ascending num */
};
/* 1 when path is a channels INI (read into cell), 0 when it has no
 * [CHANNEL_n] section (a machine INI: cell->n is 0), or -1 with d->code
 * set and d->line the line at fault (0: the whole file) and d->msg what is
 * wrong (without the path: the caller prints PATH:LINE: error: MSG). */
int ncp_cell_load(struct ncp_cell *cell, const char *path, struct ncp_diag *d);
/* The channel's BACKEND and DP over its machine's (cfg, loaded from
 * ch->config): NCP_OK, or NCP_ERR_SEMANTIC with d->line the channels INI's
 * line (a DP on a channel whose backend is not lcm). */
int ncp_cell_apply(const struct ncp_cell_channel *ch, struct ncp_machine_cfg *cfg,
                   struct ncp_diag *d);

/* ---- the table of keys (ini_keys.c) ---------------------------------------
 * The machine INI's sections and keys: every one the reader
 * (ncp_machine_cfg_load, src/config/config.c) takes, with the values it
 * takes, its default and its meaning.
 *
 * Invariant: the reader refuses a key this table does not list before it
 * looks at its value, and ncpar.ini(5) is printed from this table by a tool
 * (tools/ini-man.c) that first loads a probe INI for each row through the
 * reader and stops the build when the reader refuses a value the row allows
 * or takes one it rules out. So the page and the reader cannot disagree
 * about which keys exist, nor about their ranges.
 *
 * A section or key name may hold one placeholder: <L> an axis letter of
 * XYZABCUVW, <n> a whole number (the reader bounds it). */
enum ncp_ini_kind {
    NCP_INI_REAL,   /* a plain decimal in [lo, hi] */
    NCP_INI_INT,    /* a whole number in [lo, hi] */
    NCP_INI_CPU,    /* a CPU of this machine, -1 (the OS chooses) .. the last one */
    NCP_INI_WORD,   /* one of the words in values, '|' between them, any case */
    NCP_INI_TEXT,   /* free form: values says which */
};

struct ncp_ini_key {
    const char *section;
    const char *key;
    enum ncp_ini_kind kind;
    double lo, hi;          /* REAL and INT */
    const char *unit;       /* "" when it has none */
    const char *values;     /* WORD: the words; TEXT: the form; else NULL */
    const char *def;        /* the default as a file would write it; NULL: required
                               (or no value when it is not given: doc says) */
    const char *example;    /* TEXT: a value the reader takes; else NULL */
    const char *probe_section; /* the section a probe puts it in, when the
                                  placeholder's first choice cannot hold it */
    const char *doc;
};

struct ncp_ini_section {
    const char *name;
    const char *doc;
};

extern const struct ncp_ini_key ncp_ini_keys[];
extern const size_t ncp_ini_n_keys;
extern const struct ncp_ini_section ncp_ini_sections[];
extern const size_t ncp_ini_n_sections;

/* The row of [sec] key (names in any case, '-' as '_'), or NULL. */
const struct ncp_ini_key *ncp_ini_key_find(const char *sec, const char *key);

#endif
