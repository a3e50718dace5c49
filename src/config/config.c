/* Machine INI (LinuxCNC style) read with libinih. Every key is known: a typo in a
 * machine file must not silently fall back to a default. */
#include "ncpar/config.h"
#include "ncpar/adcai.h"
#include "ncpar/http.h"
#include "ini_num.h"
#include "kins_cfg.h"
#include "ncpar/num.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

void ncp_machine_cfg_default(struct ncp_machine_cfg *c)
{
    memset(c, 0, sizeof *c);
    c->servo_period = 1e-3;
    c->max_linear_vel = 200.0;
    for (int i = 0; i < NCP_AXES; i++) {
        c->axis[i] = (struct ncp_axis_cfg){ .min_limit = -500.0, .max_limit = 500.0,
                                            .max_vel = 200.0, .max_acc = 2000.0,
                                            .max_jerk = 100000.0, .ferror = 1.0 };
    }
    c->axis[2].min_limit = -250.0;
    c->axis[2].max_limit = 50.0;
    c->axis_mask = NCP_AXES_XYZ;
    c->lookahead = 200;
    c->profile = NCP_PROFILE_TRAPEZOID;
    c->setpoint_ring = 1024;
    /* Plant 250/(s(s+25)): KP 40, KD 0.46 put the closed loop at ~100 rad/s with
     * damping 0.7, well inside a 1 kHz loop. FF1 = 25/250 cancels the plant's
     * velocity lag exactly, FF2 = 1/250 its inertia, so a constant-velocity line
     * has no steady-state following error at any feed. */
    c->kp = 40.0;
    c->kd = 0.46;
    c->ff1 = 0.1;
    c->ff2 = 0.004;
    c->position = (struct ncp_rt_place){ -1, SCHED_FIFO, 90 };
    c->planner = (struct ncp_rt_place){ -1, SCHED_OTHER, 0 };
    c->interp = (struct ncp_rt_place){ -1, SCHED_OTHER, 0 };
    c->backend = NCP_BACKEND_SIM;
    ncp_op_cfg_default(&c->op);
    /* 10 heartbeats may go missing before the drive counts as lost; SDO
     * answers come within a few ms from any drive that is there at all */
    c->can.heartbeat_period_ms = 50;
    c->can.heartbeat_timeout_ms = 500;
    c->can.sdo_timeout_ms = 200;
    /* three of our heartbeats may go missing before the drives stop on their own */
    c->can.master_node = 127;
    c->can.hb_consumer_ms = 150;
    c->can.rpdo_timeout_ms = 100;
    c->can.abort_option = 3;
    c->can.fault_reaction = 2;
    c->default_linear_vel = 10.0;
    ncp_io_cfg_default(&c->io);
    ncp_inject_cfg_default(&c->inject);
    ncp_sched_cfg_default(&c->sched);
    snprintf(c->lcm.prefix, sizeof c->lcm.prefix, "NCP_");
    c->lcm.status_hz = 50.0;
    c->lcm.dp = 5;
    c->lcm.max_lost_periods = 20;
    c->lcm.heartbeat_period_ms = 20;
    c->lcm.heartbeat_timeout_ms = 200;
    c->lcm.axis_wait_ms = 5000;
    c->lcm.inject_seed = 1;
    c->lcm.clock = NCP_LCM_CLOCK_MONOTONIC;
    c->lcm.clock_tolerance_us = 1000;
    snprintf(c->lcm.interface, sizeof c->lcm.interface, "lo");
    c->lcm.max_age_ms = 2000;
    ncp_machine_joints_from_axes(c);
}

/* The safety keys every axis must state: a machine must never run on a limit
 * nobody wrote down. MAX_JERK joins them under PROFILE = scurve. */
enum { AK_MIN_LIMIT, AK_MAX_LIMIT, AK_MAX_VELOCITY, AK_MAX_ACCELERATION, AK_MAX_JERK, AK_FERROR,
       AK_COUNT };
static const char *const axis_required[] = { "MIN_LIMIT", "MAX_LIMIT", "MAX_VELOCITY",
                                             "MAX_ACCELERATION", "FERROR" };

#define MAX_SEEN 512 /* more than there are known keys: an unknown one stops the load */

struct load_ctx {
    struct ncp_machine_cfg *c;
    const char *path;
    struct ncp_diag *d;
    FILE *f;
    int failed;
    unsigned line;              /* lines read so far: the handler's key is on this one */
    unsigned axis_line[NCP_AXES]; /* line of [AXIS_n], 0 = not in the file */
    unsigned axis_set[NCP_AXES];  /* AK_* bits given */
    unsigned profile_line;
    unsigned coords_line;       /* [TRAJ] COORDINATES, 0 = not given (XYZ) */
    char coords[16];            /* as the file wrote it */
    struct kins_load kl;        /* [KINS], [JOINT_n] */
    struct seen { char sec[16], key[32]; unsigned line; } seen[MAX_SEEN];
    int n_seen;
    struct { char name[16]; unsigned line; } sections[40];
    int n_sections;
};

__attribute__((format(printf, 3, 4)))
static int fail_at(struct load_ctx *lc, unsigned line, const char *fmt, ...)
{
    if (lc->failed)
        return 0;
    lc->failed = 1;
    char msg[NCP_DIAG_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ncp_diag_set(lc->d, NCP_ERR_SEMANTIC, line, 0, "%s: %s", lc->path, msg);
    return 0;
}

/* x as the INI would write it: no exponent, no trailing zeros */
static void plain(char *buf, size_t len, double x)
{
    snprintf(buf, len, "%.9f", x);
    char *dot = strchr(buf, '.');
    if (!dot)
        return;
    char *e = buf + strlen(buf) - 1;
    while (e > dot && *e == '0')
        *e-- = '\0';
    if (e == dot)
        *e = '\0';
}

/* The range a key takes, for its error message: "UNIT from LO to HI". */
static void range(char *why, size_t len, const char *unit, double lo, double hi)
{
    char a[48], b[48];
    plain(a, sizeof a, lo);
    plain(b, sizeof b, hi);
    snprintf(why, len, "%s%sfrom %s to %s", unit, *unit ? " " : "", a, b);
}

static int real(const char *v, double lo, double hi, double *out, const char *unit, char *why,
                size_t len)
{
    if (ncp_ini_number(v, lo, hi, out) == 0)
        return 1;
    range(why, len, unit, lo, hi);
    return -1;
}

static int integer(const char *v, int lo, int hi, int *out)
{
    double x;
    if (ncp_ini_number(v, lo, hi, &x) || x != floor(x))
        return -1;
    *out = (int)x;
    return 0;
}

static int whole(const char *v, int lo, int hi, int *out, const char *unit, char *why, size_t len)
{
    if (integer(v, lo, hi, out) == 0)
        return 1;
    snprintf(why, len, "%s%sa whole number from %d to %d", unit, *unit ? ", " : "", lo, hi);
    return -1;
}

/* An axis key: returns 1 if known and set (*bit: its AK_* bit, 0 for the
 * others), 0 if unknown, -1 if the value is bad. */
static int axis_key(struct ncp_axis_cfg *a, const char *k, const char *v, unsigned *bit,
                    char *why, size_t len)
{
    const struct { const char *name; double *dst; double lo, hi; const char *unit; int ak; } keys[] = {
        { "MIN_LIMIT", &a->min_limit, -1e6, 1e6, "mm", AK_MIN_LIMIT },
        { "MAX_LIMIT", &a->max_limit, -1e6, 1e6, "mm", AK_MAX_LIMIT },
        { "MAX_VELOCITY", &a->max_vel, 1e-6, 1e6, "mm/s", AK_MAX_VELOCITY },
        { "MAX_ACCELERATION", &a->max_acc, 1e-6, 1e8, "mm/s^2", AK_MAX_ACCELERATION },
        { "MAX_JERK", &a->max_jerk, 0, 1e12, "mm/s^3", AK_MAX_JERK },
        { "FERROR", &a->ferror, 1e-9, 1e6, "mm", AK_FERROR },
        { "COUNTS_PER_MM", &a->counts_per_mm, 1e-3, 1e9, "counts/mm", -1 },
    };
    *bit = 0;
    if (!strcasecmp(k, "NODE_ID"))
        return whole(v, 1, 127, &a->node_id, "CANopen node", why, len);
    if (!strncasecmp(k, "HOME", 4))
        return ncp_home_cfg_key(a, k, v, why, len);
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcasecmp(k, keys[i].name) != 0)
            continue;
        *bit = keys[i].ak >= 0 ? 1u << keys[i].ak : 0;
        return real(v, keys[i].lo, keys[i].hi, keys[i].dst, keys[i].unit, why, len);
    }
    return 0;
}

/* A CPU this machine has (-1: the OS chooses): a placement on a CPU that is
 * not there must not turn into a silent move to another one. */
static int cpu_key(const char *v, int *cpu, char *why, size_t len)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1)
        n = 1;
    if (integer(v, -1, (int)n - 1, cpu) == 0)
        return 1;
    snprintf(why, len, "this machine has CPUs 0..%ld; -1 lets the OS choose", n - 1);
    return -1;
}

static int rt_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                  size_t len)
{
    const struct { const char *prefix; struct ncp_rt_place *pl; } threads[] = {
        { "POSITION_", &c->position }, { "PLANNER_", &c->planner }, { "INTERP_", &c->interp },
    };
    for (size_t i = 0; i < sizeof threads / sizeof threads[0]; i++) {
        size_t n = strlen(threads[i].prefix);
        if (strncasecmp(k, threads[i].prefix, n) != 0)
            continue;
        if (!strcasecmp(k + n, "PRIORITY")) {
            /* 0 is SCHED_OTHER, as in the thread maps' POLICY = other */
            if (whole(v, 0, 99, &threads[i].pl->priority, "0: SCHED_OTHER, 1..99: SCHED_FIFO",
                      why, len) < 0)
                return -1;
            threads[i].pl->policy = threads[i].pl->priority > 0 ? SCHED_FIFO : SCHED_OTHER;
            return 1;
        }
        if (!strcasecmp(k + n, "CPU"))
            return cpu_key(v, &threads[i].pl->cpu, why, len);
    }
    return 0;
}

/* A key that takes one of two words (any case): *second says which; else
 * why names both. */
static int either(const char *v, const char *first, const char *other, int *second, char *why,
                  size_t len)
{
    *second = !strcasecmp(v, other);
    if (*second || !strcasecmp(v, first))
        return 0;
    snprintf(why, len, "%s or %s", first, other);
    return -1;
}

/* What cnc-run run and serve drive when no --backend says; an LLC
 * (cnc-axis) takes its own drive from its --backend, never from here. */
static int backend_key(struct ncp_machine_cfg *c, const char *v, char *why, size_t len)
{
    static const char *const names[] = { "sim", "socketcan", "lcm" };
    static const enum ncp_backend_kind kinds[] = { NCP_BACKEND_SIM, NCP_BACKEND_SOCKETCAN,
                                                   NCP_BACKEND_LCM };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (!strcasecmp(v, names[i])) {
            c->backend = kinds[i];
            return 1;
        }
    return snprintf(why, len, "sim, socketcan or lcm"), -1;
}

static int planner_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                       size_t len)
{
    if (!strcasecmp(k, "LOOKAHEAD"))
        return whole(v, 2, 100000, &c->lookahead, "segments", why, len);
    if (!strcasecmp(k, "SETPOINT_RING"))
        return whole(v, 4, 1 << 20, &c->setpoint_ring, "planning periods", why, len);
    int second;
    if (!strcasecmp(k, "PROFILE")) {
        if (either(v, "trapezoid", "scurve", &second, why, len) < 0)
            return -1;
        c->profile = second ? NCP_PROFILE_SCURVE : NCP_PROFILE_TRAPEZOID;
        return 1;
    }
    if (!strcasecmp(k, "NCK")) {
        if (either(v, "adcbi", "adcai", &second, why, len) < 0)
            return -1;
        c->nck = second ? NCP_NCK_ADCAI : NCP_NCK_ADCBI;
        return 1;
    }
    return 0;
}

static int sim_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                   size_t len)
{
    const struct { const char *name; double *dst; } keys[] = {
        { "KP", &c->kp }, { "KI", &c->ki }, { "KD", &c->kd }, { "FF1", &c->ff1 }, { "FF2", &c->ff2 },
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcasecmp(k, keys[i].name))
            return real(v, 0, 1e9, keys[i].dst, "", why, len);
    return 0;
}

static int can_key(struct ncp_can_cfg *c, const char *k, const char *v, char *why, size_t len)
{
    if (!strcasecmp(k, "INTERFACE")) {
        /* what the kernel accepts as an interface name (IFNAMSIZ) */
        size_t n = strlen(v);
        if (n == 0 || n >= sizeof c->interface || strpbrk(v, " \t/:"))
            return snprintf(why, len, "an interface name of 1 to %zu characters without "
                                      "blanks, / or :", sizeof c->interface - 1), -1;
        memcpy(c->interface, v, n + 1);
        return 1;
    }
    const struct { const char *name; int *dst; int lo, hi; } keys[] = {
        { "HEARTBEAT_PERIOD_MS", &c->heartbeat_period_ms, 1, 65535 },
        { "HEARTBEAT_TIMEOUT_MS", &c->heartbeat_timeout_ms, 1, 600000 },
        { "SDO_TIMEOUT_MS", &c->sdo_timeout_ms, 1, 600000 },
        { "HEARTBEAT_CONSUMER_MS", &c->hb_consumer_ms, 1, 65535 },
        { "RPDO_TIMEOUT_MS", &c->rpdo_timeout_ms, 0, 65535 },
    };
    const struct { const char *name; int *dst; int lo, hi; const char *unit; } codes[] = {
        { "MASTER_NODE", &c->master_node, 0, 127, "a CANopen node-ID (0: off)" },
        { "ABORT_CONNECTION_OPTION", &c->abort_option, 0, 3, "CiA 402 object 0x6007" },
        { "FAULT_REACTION_OPTION", &c->fault_reaction, 0, 4, "CiA 402 object 0x605E" },
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcasecmp(k, keys[i].name))
            return whole(v, keys[i].lo, keys[i].hi, keys[i].dst, "ms", why, len);
    for (size_t i = 0; i < sizeof codes / sizeof codes[0]; i++)
        if (!strcasecmp(k, codes[i].name))
            return whole(v, codes[i].lo, codes[i].hi, codes[i].dst, codes[i].unit, why, len);
    return 0;
}

const char *ncp_lcm_clock_name(int mode)
{
    static const char *const names[] = { "monotonic", "probe", "ptp" };
    return mode >= NCP_LCM_CLOCK_MONOTONIC && mode <= NCP_LCM_CLOCK_PTP ? names[mode] : names[0];
}

static int lcm_key(struct ncp_lcm_cfg *l, const char *k, const char *v, char *why, size_t len)
{
    if (!strcasecmp(k, "URL")) {
        size_t n = strlen(v);
        if (n == 0 || n >= sizeof l->url)
            return snprintf(why, len, "1 to %zu characters", sizeof l->url - 1), -1;
        memcpy(l->url, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "CHANNEL_PREFIX")) {
        /* LCM channel names: letters, digits and _ keep lcm-spy's filters simple */
        size_t n = strlen(v);
        if (n >= sizeof l->prefix || strspn(v, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") != n)
            return snprintf(why, len, "letters, digits and _, up to %zu of them",
                            sizeof l->prefix - 1), -1;
        memcpy(l->prefix, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "STATUS_HZ"))
        return real(v, 0, 1000, &l->status_hz, "Hz (0: only at changes)", why, len);
    if (!strcasecmp(k, "KEY_FILE")) {
        size_t n = strlen(v);
        if (n == 0 || n >= sizeof l->key_file)
            return snprintf(why, len, "a path of 1 to %zu characters", sizeof l->key_file - 1),
                   -1;
        memcpy(l->key_file, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "INTERFACE")) {
        size_t n = strlen(v);
        if (n >= sizeof l->interface || strpbrk(v, "/ \t") != NULL)
            return snprintf(why, len, "a network interface's name (lo, eth0, ...), up to %zu "
                                      "characters, or empty for any",
                            sizeof l->interface - 1),
                   -1;
        memcpy(l->interface, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "INJECT_LOSS"))
        return real(v, 0, 1, &l->inject_loss, "(a fraction)", why, len);
    if (!strcasecmp(k, "CLOCK")) {
        for (int i = NCP_LCM_CLOCK_MONOTONIC; i <= NCP_LCM_CLOCK_PTP; i++)
            if (!strcasecmp(v, ncp_lcm_clock_name(i))) {
                l->clock = (enum ncp_lcm_clock)i;
                return 1;
            }
        return snprintf(why, len, "monotonic (one host), probe (estimated from round trips) "
                                  "or ptp (CLOCK_REALTIME kept by ptp4l/phc2sys)"), -1;
    }
    static const struct { const char *name; int lo, hi; const char *unit; } ints[] = {
        { "DP", 1, 5, "(a distribution point)" },
        { "MAX_LOST_PERIODS", 1, 100000, "periods" },
        { "HEARTBEAT_PERIOD_MS", 1, 10000, "ms" },
        { "HEARTBEAT_TIMEOUT_MS", 2, 60000, "ms" },
        { "AXIS_WAIT_MS", 1, 600000, "ms" },
        { "INJECT_DELAY_US", 0, 1000000, "us" },
        { "INJECT_SEED", 0, 2147483647, "" },
        { "CLOCK_TOLERANCE_US", 1, 10000000, "us" },
        { "STATUS_NEEDS_KEY", 0, 1, "(0 or 1)" },
        { "MAX_AGE_MS", 0, 3600000, "ms (0: no limit)" },
    };
    int *dst[] = { &l->dp, &l->max_lost_periods, &l->heartbeat_period_ms,
                   &l->heartbeat_timeout_ms, &l->axis_wait_ms, &l->inject_delay_us,
                   &l->inject_seed, &l->clock_tolerance_us, &l->status_needs_key,
                   &l->max_age_ms };
    _Static_assert(sizeof ints / sizeof ints[0] == sizeof dst / sizeof dst[0], "one each");
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++)
        if (!strcasecmp(k, ints[i].name))
            return whole(v, ints[i].lo, ints[i].hi, dst[i], ints[i].unit, why, len);
    return 0;
}

static int traj_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                    size_t len)
{
    double x;
    if (!strcasecmp(k, "MAX_LINEAR_VELOCITY"))
        return real(v, 1e-6, 1e6, &c->max_linear_vel, "mm/s", why, len);
    if (!strcasecmp(k, "PLANNING_PERIOD")) {
        if (real(v, 125000, 100000000, &x, "ns", why, len) < 0)
            return -1;
        c->planning_period = x * 1e-9;
        return 1;
    }
    if (!strcasecmp(k, "DEFAULT_LINEAR_ACCELERATION"))
        return real(v, 0, 1e8, &c->default_linear_acc, "mm/s^2 (0: the axes' limits)", why, len);
    if (!strcasecmp(k, "DEFAULT_LINEAR_VELOCITY"))
        return real(v, 1e-6, 1e6, &c->default_linear_vel, "mm/s", why, len);
    if (!strcasecmp(k, "NO_FORCE_HOMING"))
        return integer(v, 0, 1, &c->no_force_homing) ? snprintf(why, len, "0 or 1"), -1 : 1;
    return 0;
}

/* [AXIS_X] -> 0 .. [AXIS_W] -> 8, else -1 */
static int axis_index(const char *sec)
{
    if (strncasecmp(sec, "AXIS_", 5) != 0 || strlen(sec) != 6)
        return -1;
    const char *p = strchr(NCP_AXIS_LETTERS, sec[5] & ~0x20);
    return p && *p ? (int)(p - NCP_AXIS_LETTERS) : -1;
}

/* [TRAJ] COORDINATES: each of X Y Z A B C U V W at most once (LinuxCNC
 * repeats a letter for a gantry's second joint: that needs a joint layer
 * this machine model does not have yet). */
static int coordinates_key(struct load_ctx *lc, const char *v, char *why, size_t len)
{
    unsigned mask = 0;
    size_t n = 0;
    for (const char *p = v; *p; p++) {
        if (*p == ' ' || *p == '\t')
            continue;
        const char *q = strchr(NCP_AXIS_LETTERS, *p & ~0x20);
        if (!q || !*q || (mask & NCP_AXIS_BIT(q - NCP_AXIS_LETTERS)))
            return snprintf(why, len, "axis letters from XYZABCUVW, each once, e.g. XYZ or XYZA"),
                   -1;
        mask |= NCP_AXIS_BIT(q - NCP_AXIS_LETTERS);
        if (n + 1 < sizeof lc->coords)
            lc->coords[n++] = (char)(*p & ~0x20);
    }
    if (!mask)
        return snprintf(why, len, "at least one axis letter, e.g. XYZ"), -1;
    lc->coords[n] = '\0';
    lc->c->axis_mask = mask;
    lc->coords_line = lc->line;
    return 1;
}

/* [HTTP]: the lists are checked here, so that a mistyped origin is an
 * error naming its line before anything listens. */
static int http_key(struct ncp_http_cfg *h, const char *k, const char *v, char *why, size_t len)
{
    int origins = !strcasecmp(k, "ALLOW_ORIGIN");
    if (!origins && strcasecmp(k, "ALLOW_HOST") != 0)
        return 0;
    char *dst = origins ? h->allow_origin : h->allow_host;
    if (strlen(v) >= sizeof h->allow_origin)
        return snprintf(why, len, "at most %zu characters", sizeof h->allow_origin - 1), -1;
    if (ncp_http_allow_list_ok(v, origins, why, len))
        return -1;
    snprintf(dst, sizeof h->allow_origin, "%s", v);
    return 1;
}

static int known_section(const char *sec)
{
    static const char *const names[] = { "EMCMOT", "TRAJ",   "LCM",   "PLANNER",
                                         "SIM",    "RT",     "CAN",   "SPINDLE_0",
                                         "EMCIO",  "INJECT", "SCHED", "HTTP",
                                         "RS274NGC", "DISPLAY" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (!strcasecmp(sec, names[i]))
            return 1;
    return axis_index(sec) >= 0 || !strcasecmp(sec, "KINS") || ncp_kins_joint_section(sec) >= 0;
}

static int dispatch(struct load_ctx *lc, const char *sec, const char *k, const char *v,
                    char *why, size_t len)
{
    struct ncp_machine_cfg *c = lc->c;
    if (!strcasecmp(sec, "EMCMOT")) {
        if (!strcasecmp(k, "BACKEND"))
            return backend_key(c, v, why, len);
        if (strcasecmp(k, "SERVO_PERIOD") != 0)
            return 0;
        /* 125 us .. 10 ms: outside that the plant model and the loop make no sense */
        double x;
        if (real(v, 125000, 10000000, &x, "ns", why, len) < 0)
            return -1;
        c->servo_period = x * 1e-9;
        return 1;
    }
    if (!strcasecmp(sec, "TRAJ"))
        return !strcasecmp(k, "COORDINATES") ? coordinates_key(lc, v, why, len)
                                             : traj_key(c, k, v, why, len);
    if (!strcasecmp(sec, "LCM"))
        return lcm_key(&c->lcm, k, v, why, len);
    if (!strcasecmp(sec, "HTTP"))
        return http_key(&c->http, k, v, why, len);
    int ax = axis_index(sec);
    if (ax >= 0 && !strcasecmp(k, "WRAPPED_ROTARY")) {
        if (!ncp_axis_rotary(ax))
            return snprintf(why, len, "only the rotary axes A, B and C wrap"), -1;
        return integer(v, 0, 1, &c->axis[ax].wrapped) ? snprintf(why, len, "0 or 1"), -1 : 1;
    }
    if (ax >= 0) {
        unsigned bit;
        int r = axis_key(&c->axis[ax], k, v, &bit, why, len);
        if (r == 1)
            lc->axis_set[ax] |= bit;
        return r;
    }
    if (!strcasecmp(sec, "PLANNER")) {
        if (!strcasecmp(k, "PROFILE"))
            lc->profile_line = lc->line;
        return planner_key(c, k, v, why, len);
    }
    if (!strcasecmp(sec, "SIM")) {
        int r = sim_key(c, k, v, why, len);
        if (r == 0 && (r = ncp_home_switch_key(c, k, v, why, len)) == -2)
            r = ncp_io_cfg_key(&c->io, sec, k, v, why, len);
        return r;
    }
    if (!strcasecmp(sec, "RT")) {
        int r = rt_key(c, k, v, why, len);
        return r ? r : ncp_inject_ini_key(&c->inject, sec, k, v, why, len);
    }
    if (!strcasecmp(sec, "INJECT"))
        return ncp_inject_ini_key(&c->inject, sec, k, v, why, len);
    if (!strcasecmp(sec, "SCHED"))
        return ncp_sched_ini_key(&c->sched, k, v, why, len);
    if (!strcasecmp(sec, "CAN"))
        return can_key(&c->can, k, v, why, len);
    /* [RS274NGC] and [DISPLAY] are shared: the operator's keys (the
     * parameter file, the overrides) first, then the interpreter's */
    int r = ncp_op_cfg_key(&c->op, lc->path, sec, k, v, why, len);
    if (r == 1 || r == -1)
        return r;
    int rr = ncp_rs274_cfg_key(&c->rs274, lc->path, sec, k, v, why, len);
    if (rr != -2)
        return rr;
    if (r == 0)
        return 0;
    r = ncp_kins_cfg_key(&lc->kl, c, sec, k, v, lc->line, why, len);
    if (r != -2)
        return r;
    return ncp_io_cfg_key(&c->io, sec, k, v, why, len);
}

/* A key given twice would leave only its last value in force, whichever the
 * writer meant: refused, naming both lines. */
static int duplicate(struct load_ctx *lc, const char *sec, const char *k)
{
    for (int i = 0; i < lc->n_seen; i++)
        if (!strcasecmp(lc->seen[i].sec, sec) && !strcasecmp(lc->seen[i].key, k))
            return fail_at(lc, lc->line, "[%s] %s given twice (first on line %u); each key "
                                         "once", sec, k, lc->seen[i].line), 1;
    if (lc->n_seen < MAX_SEEN) {
        struct seen *s = &lc->seen[lc->n_seen++];
        snprintf(s->sec, sizeof s->sec, "%s", sec);
        snprintf(s->key, sizeof s->key, "%s", k);
        s->line = lc->line;
    }
    return 0;
}

static int on_key(void *user, const char *sec, const char *k, const char *v)
{
    struct load_ctx *lc = user;
    if (lc->failed)
        return 0;
    if (!*sec)
        return fail_at(lc, lc->line, "%s outside of a [section]", k);
    char why[112] = "";
    /* a key ncpar.ini(5) does not list is unknown, whatever dispatch knows */
    int r = ncp_ini_key_find(sec, k) ? dispatch(lc, sec, k, v, why, sizeof why) : 0;
    /* REMAP is LinuxCNC's one key given once per remapped code */
    if (r == 1 && !strcasecmp(sec, "RS274NGC") && !strcasecmp(k, "REMAP"))
        return 1;
    if (r == 1)
        return duplicate(lc, sec, k) ? 0 : 1;
    if (r == -2)
        return fail_at(lc, lc->line, "unknown section [%s]", sec);
    if (r == 0)
        return fail_at(lc, lc->line, "[%s] unknown key %s", sec, k);
    return fail_at(lc, lc->line, "[%s] %s: bad value '%s'%s%s%s", sec, k, v, why[0] ? " (" : "",
                   why, why[0] ? ")" : "");
}

/* inih hands over one line per call: counting them here gives each key its
 * line, and section headers are checked even when no key follows them. */
static char *read_line(char *str, int n, void *stream)
{
    struct load_ctx *lc = stream;
    char *s = fgets(str, n, lc->f);
    if (!s)
        return NULL;
    lc->line++;
    const char *p = s + strspn(s, " \t");
    const char *close = *p == '[' ? strchr(p, ']') : NULL;
    if (!close || lc->failed)
        return s;
    char name[32];
    size_t len = (size_t)(close - p - 1);
    if (len >= sizeof name) {
        fail_at(lc, lc->line, "unknown section [%.*s]", (int)len, p + 1);
        return s;
    }
    memcpy(name, p + 1, len);
    name[len] = '\0';
    if (!known_section(name)) {
        fail_at(lc, lc->line, "unknown section [%s]", name);
        return s;
    }
    for (int i = 0; i < lc->n_sections; i++)
        if (!strcasecmp(lc->sections[i].name, name)) {
            fail_at(lc, lc->line, "[%s] given twice (first on line %u); each section once",
                    name, lc->sections[i].line);
            return s;
        }
    /* known sections are fewer than the slots */
    if (lc->n_sections < (int)(sizeof lc->sections / sizeof lc->sections[0])) {
        snprintf(lc->sections[lc->n_sections].name, sizeof lc->sections[0].name, "%s", name);
        lc->sections[lc->n_sections++].line = lc->line;
    }
    int ax = axis_index(name);
    if (ax >= 0)
        lc->axis_line[ax] = lc->line;
    return s;
}

int ncp_machine_cfg_ipo_ratio(const struct ncp_machine_cfg *c)
{
    if (c->planning_period <= 0)
        return 1;
    double k = c->planning_period / c->servo_period;
    long r = lround(k);
    /* the INI gives whole ns: allow for their rounding only */
    if (r < 1 || r > 1000 || fabs(k - (double)r) * c->servo_period > 0.5e-9)
        return 0;
    return (int)r;
}

/* Every axis states its limits: the built-in values are a simulated mill's,
 * never a guess for a real machine. */
static int check_axes(struct load_ctx *lc)
{
    unsigned need = (1u << AK_MIN_LIMIT) | (1u << AK_MAX_LIMIT) | (1u << AK_MAX_VELOCITY) |
                    (1u << AK_MAX_ACCELERATION) | (1u << AK_FERROR);
    if (lc->c->profile == NCP_PROFILE_SCURVE)
        need |= 1u << AK_MAX_JERK;
    const char *coords = lc->coords_line ? lc->coords : "XYZ";
    char where[48] = "(the default)";
    if (lc->coords_line)
        snprintf(where, sizeof where, "(line %u)", lc->coords_line);
    for (int i = 0; i < NCP_AXES; i++) {
        int want = (lc->c->axis_mask & NCP_AXIS_BIT(i)) != 0;
        if (!want && lc->axis_line[i])
            return fail_at(lc, lc->axis_line[i], "[AXIS_%c] is for an axis [TRAJ] COORDINATES = "
                                                 "%s %s does not name: add %c to COORDINATES "
                                                 "or remove the section",
                           NCP_AXIS_LETTERS[i], coords, where, NCP_AXIS_LETTERS[i]), -1;
        if (!want)
            continue;
        if (!lc->axis_line[i])
            return fail_at(lc, lc->coords_line, "[AXIS_%c] missing: [TRAJ] COORDINATES = %s %s "
                                  "names %c, and every axis needs MIN_LIMIT, "
                                  "MAX_LIMIT, MAX_VELOCITY, MAX_ACCELERATION and FERROR",
                           NCP_AXIS_LETTERS[i], coords, where, NCP_AXIS_LETTERS[i]), -1;
        unsigned missing = need & ~lc->axis_set[i];
        if (!missing)
            continue;
        int k = 0;
        while (!(missing & (1u << k)))
            k++;
        if (k == AK_MAX_JERK)
            return fail_at(lc, lc->axis_line[i], "[AXIS_%c] MAX_JERK missing: PROFILE = scurve "
                                                 "(line %u) limits every axis's jerk",
                           NCP_AXIS_LETTERS[i], lc->profile_line), -1;
        return fail_at(lc, lc->axis_line[i], "[AXIS_%c] %s missing: every axis needs MIN_LIMIT, "
                                             "MAX_LIMIT, MAX_VELOCITY, MAX_ACCELERATION and FERROR",
                       NCP_AXIS_LETTERS[i], axis_required[k > AK_MAX_JERK ? k - 1 : k]), -1;
    }
    return 0;
}

/* Where the file gave [sec] key (0: it did not), for the checks across keys. */
static unsigned key_line(const struct load_ctx *lc, const char *sec, const char *k)
{
    for (int i = 0; i < lc->n_seen; i++)
        if (!strcasecmp(lc->seen[i].sec, sec) && !strcasecmp(lc->seen[i].key, k))
            return lc->seen[i].line;
    return 0;
}

static int check_cfg(struct load_ctx *lc)
{
    const struct ncp_machine_cfg *c = lc->c;
    int ratio = ncp_machine_cfg_ipo_ratio(c);
    if (ratio == 0)
        return fail_at(lc, key_line(lc, "TRAJ", "PLANNING_PERIOD"), "[TRAJ] PLANNING_PERIOD %.0f ns must be a whole multiple of "
                              "[EMCMOT] SERVO_PERIOD %.0f ns",
                       c->planning_period * 1e9, c->servo_period * 1e9), -1;
    for (int i = 0; i < NCP_AXES; i++) {
        if (!(c->axis_mask & NCP_AXIS_BIT(i)))
            continue;
        if (c->axis[i].min_limit >= c->axis[i].max_limit)
            return fail_at(lc, lc->axis_line[i], "[AXIS_%c] MIN_LIMIT must be below MAX_LIMIT",
                           NCP_AXIS_LETTERS[i]), -1;
        for (int j = 0; j < i; j++)
            if ((c->axis_mask & NCP_AXIS_BIT(j)) && c->axis[i].node_id &&
                c->axis[i].node_id == c->axis[j].node_id)
                return fail_at(lc, lc->axis_line[i],
                               "[AXIS_%c] NODE_ID %d is already the node of [AXIS_%c]",
                               NCP_AXIS_LETTERS[i], c->axis[i].node_id, NCP_AXIS_LETTERS[j]), -1;
        char why[160];
        if (ncp_home_cfg_check(c, i, why, sizeof why))
            return fail_at(lc, lc->axis_line[i], "[AXIS_%c] %s", NCP_AXIS_LETTERS[i], why), -1;
        /* homing moves the planned axes; a switch sits on a joint */
        if (ncp_kins_active(c) && c->axis[i].home_search_vel != 0)
            return fail_at(lc, lc->axis_line[i],
                           "[AXIS_%c] HOME_SEARCH_VEL: homing on switches is not supported with "
                           "[KINS] KINEMATICS = %s (the switches sit on joints); home without "
                           "switches (HOME_SEARCH_VEL = 0)",
                           NCP_AXIS_LETTERS[i], ncp_kins_name(c->kins.type)), -1;
    }
    for (int i = 0; i < NCP_AXES; i++) {
        if ((c->axis_mask & NCP_AXIS_BIT(i)) || !c->axis[i].have_home_switch)
            continue;
        char key[16];
        snprintf(key, sizeof key, "HOME_SWITCH_%c", NCP_AXIS_LETTERS[i]);
        return fail_at(lc, key_line(lc, "SIM", key), "[SIM] %s: the machine has no axis %c "
                       "([TRAJ] COORDINATES)", key, NCP_AXIS_LETTERS[i]), -1;
    }
    char op_why[160];
    if (ncp_op_cfg_check(&c->op, op_why, sizeof op_why))
        return fail_at(lc, key_line(lc, "DISPLAY", "MIN_SPINDLE_OVERRIDE"), "%s", op_why), -1;
    if (c->lcm.heartbeat_timeout_ms <= c->lcm.heartbeat_period_ms)
        return fail_at(lc, key_line(lc, "LCM", "HEARTBEAT_TIMEOUT_MS"),
                       "[LCM] HEARTBEAT_TIMEOUT_MS %d must be longer than HEARTBEAT_PERIOD_MS %d",
                       c->lcm.heartbeat_timeout_ms, c->lcm.heartbeat_period_ms), -1;
    if (c->can.master_node && c->can.hb_consumer_ms <= c->can.heartbeat_period_ms)
        return fail_at(lc, key_line(lc, "CAN", "HEARTBEAT_CONSUMER_MS"),
                       "[CAN] HEARTBEAT_CONSUMER_MS %d must be longer than HEARTBEAT_PERIOD_MS "
                       "%d (our heartbeat's period)",
                       c->can.hb_consumer_ms, c->can.heartbeat_period_ms), -1;
    for (int i = 0; c->can.master_node && i < NCP_AXES; i++)
        if ((c->axis_mask & NCP_AXIS_BIT(i)) && c->axis[i].node_id == c->can.master_node)
            return fail_at(lc, key_line(lc, "CAN", "MASTER_NODE"),
                           "[CAN] MASTER_NODE %d is the NODE_ID of [AXIS_%c]",
                           c->can.master_node, NCP_AXIS_LETTERS[i]), -1;
    if (c->can.heartbeat_timeout_ms <= c->can.heartbeat_period_ms)
        return fail_at(lc, key_line(lc, "CAN", "HEARTBEAT_TIMEOUT_MS"), "[CAN] HEARTBEAT_TIMEOUT_MS %d must be longer than "
                              "HEARTBEAT_PERIOD_MS %d",
                       c->can.heartbeat_timeout_ms, c->can.heartbeat_period_ms), -1;
    /* a late planner thread makes the position loop slow down along the path
     * on what is left in the ring (src/rt/nck.c): half a stop from the top
     * speed at half the weakest axis's acceleration has to fit */
    double a_min = INFINITY;
    for (int i = 0; i < NCP_AXES; i++)
        if (c->axis_mask & NCP_AXIS_BIT(i))
            a_min = fmin(a_min, c->axis[i].max_acc);
    /* ADCAI fine-interpolates itself: its stream comes every servo period */
    int stream_ratio = c->nck == NCP_NCK_ADCAI ? 1 : ratio;
    double need = c->max_linear_vel / (a_min * c->servo_period) / stream_ratio + 8;
    if ((double)c->setpoint_ring < need)
        return fail_at(lc, key_line(lc, "PLANNER", "SETPOINT_RING"), "[PLANNER] SETPOINT_RING %d is too small to stop along the path "
                              "from MAX_LINEAR_VELOCITY: at least %.0f planning periods "
                              "(up to 1048576)",
                       c->setpoint_ring, ceil(need)), -1;
    return 0;
}

/* A strategy ranks the soft-RT tasks in a band of SCHED_FIFO priorities
 * below the position loop: it needs the loop on SCHED_FIFO, high enough to
 * leave the band room for the chain's tasks. */
static int check_sched(struct load_ctx *lc)
{
    const struct ncp_machine_cfg *c = lc->c;
    if (c->sched.strategy == NCP_SCHED_NONE)
        return 0;
    int ceiling = ncp_sched_ceiling(c->position.priority);
    if (c->position.policy != SCHED_FIFO || ceiling - 1 < c->sched.floor)
        return fail_at(lc, key_line(lc, "SCHED", "STRATEGY"),
                       "[SCHED] STRATEGY = %s needs [RT] POSITION_PRIORITY at least %d "
                       "(PRIORITY_MIN %d + 2): the tasks' band and the scheduler lie below "
                       "the position loop",
                       ncp_sched_strategy_name(c->sched.strategy), c->sched.floor + 2,
                       c->sched.floor), -1;
    return 0;
}

/* What ADCAI cannot do is refused with the machine file, before any program. */
static int check_adcai(struct load_ctx *lc)
{
    const struct ncp_machine_cfg *c = lc->c;
    if (c->nck != NCP_NCK_ADCAI)
        return 0;
    unsigned line = key_line(lc, "PLANNER", "NCK");
    /* its filters smooth each axis on its own: through a non-trivial
     * kinematics the joints would follow a path nobody checked */
    if (ncp_kins_active(c))
        return fail_at(lc, line, "[PLANNER] NCK = adcai needs [KINS] KINEMATICS = trivkins "
                                 "(it filters each axis on its own); use NCK = adcbi with %s",
                       ncp_kins_name(c->kins.type)), -1;
    int n[2];
    double period = c->servo_period * ncp_machine_cfg_ipo_ratio(c);
    if (ncp_adcai_windows(c, period, n) != 0)
        return fail_at(lc, line, "[PLANNER] NCK = adcai: an axis's MAX_VELOCITY over its "
                                 "MAX_ACCELERATION (or MAX_JERK) asks for an acc/dec filter "
                                 "longer than %d rough periods of %.3f ms, or a limit is "
                                 "below what 1 nm steps make at the servo period",
                       NCP_ADCAI_WINDOW_MAX, period * 1e3), -1;
    return 0;
}

static int check_kins(struct load_ctx *lc)
{
    char msg[NCP_DIAG_MSG_MAX - 64];
    unsigned line = 0;
    if (ncp_kins_cfg_finish(&lc->kl, lc->c, lc->coords_line ? lc->coords : "XYZ", msg,
                            sizeof msg, &line) == 0)
        return 0;
    return fail_at(lc, line, "%s", msg), -1;
}

int ncp_machine_cfg_load(struct ncp_machine_cfg *c, const char *path, struct ncp_diag *d)
{
    memset(d, 0, sizeof *d);
    struct load_ctx *lc = calloc(1, sizeof *lc);
    if (!lc)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: out of memory", path);
    lc->c = c;
    lc->path = path;
    lc->d = d;
    int rc = NCP_OK;
    struct stat st;
    memset(&st, 0, sizeof st);
    lc->f = fopen(path, "r");
    if (!lc->f) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: cannot open: %s", path, strerror(errno));
    } else if (fstat(fileno(lc->f), &st) != 0 || !S_ISREG(st.st_mode)) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: not a regular file%s", path,
                          S_ISDIR(st.st_mode) ? " (a directory)" : "");
    } else if (st.st_size == 0) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: empty file: a machine INI states at least "
                                               "every axis's limits", path);
    } else {
        int r = ini_parse_stream(read_line, lc, on_key, lc);
        if (r > 0 && !lc->failed)
            fail_at(lc, (unsigned)r, "expected 'KEY = VALUE' or '[SECTION]'");
        else if (r < 0 || (!lc->failed && ferror(lc->f)))
            fail_at(lc, 0, "cannot read: %s", strerror(errno));
        ncp_rs274_cfg_finish(&c->rs274);
        if (!lc->failed && check_axes(lc) == 0 && check_cfg(lc) == 0)
            if (check_kins(lc) == 0 && check_adcai(lc) == 0)
                check_sched(lc);
        rc = lc->failed ? d->code : NCP_OK;
    }
    if (lc->f)
        fclose(lc->f);
    free(lc);
    return rc;
}
