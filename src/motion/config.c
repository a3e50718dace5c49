/* Machine INI (LinuxCNC style) read with libinih. Every key is known: a typo in a
 * machine file must not silently fall back to a default. */
#include "ncpar/motion.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

void ncp_machine_cfg_default(struct ncp_machine_cfg *c)
{
    memset(c, 0, sizeof *c);
    c->servo_period = 1e-3;
    c->max_linear_vel = 200.0;
    for (int i = 0; i < NCP_AXES; i++) {
        c->axis[i] = (struct ncp_axis_cfg){ -500.0, 500.0, 200.0, 2000.0, 100000.0, 1.0, 0, 0, 0, 0 };
    }
    c->axis[2].min_limit = -250.0;
    c->axis[2].max_limit = 50.0;
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
    /* 10 heartbeats may go missing before the drive counts as lost; SDO
     * answers come within a few ms from any drive that is there at all */
    c->can.heartbeat_period_ms = 50;
    c->can.heartbeat_timeout_ms = 500;
    c->can.sdo_timeout_ms = 200;
    c->default_linear_vel = 10.0;
    ncp_io_cfg_default(&c->io);
    snprintf(c->lcm.prefix, sizeof c->lcm.prefix, "NCP_");
    c->lcm.status_hz = 50.0;
}

struct load_ctx {
    struct ncp_machine_cfg *c;
    const char *path;
    struct ncp_diag *d;
    int failed;
};

static int num(const char *v, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    while (*end == ' ' || *end == '\t')
        end++;
    if (errno || end == v || *end || !isfinite(x) || x < lo || x > hi)
        return -1;
    *out = x;
    return 0;
}

static int integer(const char *v, int lo, int hi, int *out)
{
    double x;
    if (num(v, lo, hi, &x) || x != floor(x))
        return -1;
    *out = (int)x;
    return 0;
}

/* An axis key: returns 1 if known and set, 0 if unknown, -1 if the value is bad. */
static int axis_key(struct ncp_axis_cfg *a, const char *k, const char *v)
{
    const struct { const char *name; double *dst; double lo, hi; } keys[] = {
        { "MIN_LIMIT", &a->min_limit, -1e6, 1e6 },
        { "MAX_LIMIT", &a->max_limit, -1e6, 1e6 },
        { "MAX_VELOCITY", &a->max_vel, 1e-6, 1e6 },
        { "MAX_ACCELERATION", &a->max_acc, 1e-6, 1e8 },
        { "MAX_JERK", &a->max_jerk, 0, 1e12 },
        { "FERROR", &a->ferror, 1e-9, 1e6 },
        { "COUNTS_PER_MM", &a->counts_per_mm, 1e-3, 1e9 },
        { "HOME", &a->home, -1e6, 1e6 },
        { "HOME_SEARCH_VEL", &a->home_vel, 0, 1e6 },
    };
    if (!strcasecmp(k, "NODE_ID"))
        return integer(v, 1, 127, &a->node_id) ? -1 : 1;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcasecmp(k, keys[i].name))
            return num(v, keys[i].lo, keys[i].hi, keys[i].dst) ? -1 : 1;
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
            if (integer(v, 0, 99, &threads[i].pl->priority))
                return -1;
            threads[i].pl->policy = threads[i].pl->priority > 0 ? SCHED_FIFO : SCHED_OTHER;
            return 1;
        }
        if (!strcasecmp(k + n, "CPU"))
            return cpu_key(v, &threads[i].pl->cpu, why, len);
    }
    return 0;
}

static int planner_key(struct ncp_machine_cfg *c, const char *k, const char *v)
{
    if (!strcasecmp(k, "LOOKAHEAD"))
        return integer(v, 2, 100000, &c->lookahead) ? -1 : 1;
    if (!strcasecmp(k, "SETPOINT_RING"))
        return integer(v, 4, 1 << 20, &c->setpoint_ring) ? -1 : 1;
    if (!strcasecmp(k, "PROFILE")) {
        if (!strcasecmp(v, "trapezoid"))
            c->profile = NCP_PROFILE_TRAPEZOID;
        else if (!strcasecmp(v, "scurve"))
            c->profile = NCP_PROFILE_SCURVE;
        else
            return -1;
        return 1;
    }
    return 0;
}

static int sim_key(struct ncp_machine_cfg *c, const char *k, const char *v)
{
    const struct { const char *name; double *dst; } keys[] = {
        { "KP", &c->kp }, { "KI", &c->ki }, { "KD", &c->kd }, { "FF1", &c->ff1 }, { "FF2", &c->ff2 },
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcasecmp(k, keys[i].name))
            return num(v, 0, 1e9, keys[i].dst) ? -1 : 1;
    return 0;
}

static int can_key(struct ncp_can_cfg *c, const char *k, const char *v)
{
    if (!strcasecmp(k, "INTERFACE")) {
        /* what the kernel accepts as an interface name (IFNAMSIZ) */
        size_t n = strlen(v);
        if (n == 0 || n >= sizeof c->interface || strpbrk(v, " \t/:"))
            return -1;
        memcpy(c->interface, v, n + 1);
        return 1;
    }
    const struct { const char *name; int *dst; int lo, hi; } keys[] = {
        { "HEARTBEAT_PERIOD_MS", &c->heartbeat_period_ms, 1, 65535 },
        { "HEARTBEAT_TIMEOUT_MS", &c->heartbeat_timeout_ms, 1, 600000 },
        { "SDO_TIMEOUT_MS", &c->sdo_timeout_ms, 1, 600000 },
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcasecmp(k, keys[i].name))
            return integer(v, keys[i].lo, keys[i].hi, keys[i].dst) ? -1 : 1;
    return 0;
}

static int lcm_key(struct ncp_lcm_cfg *l, const char *k, const char *v)
{
    if (!strcasecmp(k, "URL")) {
        size_t n = strlen(v);
        if (n == 0 || n >= sizeof l->url)
            return -1;
        memcpy(l->url, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "CHANNEL_PREFIX")) {
        /* LCM channel names: letters, digits and _ keep lcm-spy's filters simple */
        size_t n = strlen(v);
        if (n >= sizeof l->prefix || strspn(v, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") != n)
            return -1;
        memcpy(l->prefix, v, n + 1);
        return 1;
    }
    if (!strcasecmp(k, "STATUS_HZ"))
        return num(v, 0, 1000, &l->status_hz) ? -1 : 1;
    return 0;
}

static int dispatch(struct ncp_machine_cfg *c, const char *sec, const char *k, const char *v,
                    char *why, size_t len)
{
    double x;
    if (!strcasecmp(sec, "EMCMOT")) {
        if (strcasecmp(k, "SERVO_PERIOD") != 0)
            return 0;
        /* 125 us .. 10 ms: outside that the plant model and the loop make no sense */
        if (num(v, 125000, 10000000, &x))
            return -1;
        c->servo_period = x * 1e-9;
        return 1;
    }
    if (!strcasecmp(sec, "TRAJ")) {
        if (!strcasecmp(k, "MAX_LINEAR_VELOCITY"))
            return num(v, 1e-6, 1e6, &c->max_linear_vel) ? -1 : 1;
        if (!strcasecmp(k, "PLANNING_PERIOD")) {
            if (num(v, 125000, 100000000, &x))
                return -1;
            c->planning_period = x * 1e-9;
            return 1;
        }
        if (!strcasecmp(k, "DEFAULT_LINEAR_ACCELERATION"))
            return num(v, 0, 1e8, &c->default_linear_acc) ? -1 : 1;
        if (!strcasecmp(k, "DEFAULT_LINEAR_VELOCITY"))
            return num(v, 1e-6, 1e6, &c->default_linear_vel) ? -1 : 1;
        if (!strcasecmp(k, "NO_FORCE_HOMING"))
            return integer(v, 0, 1, &c->no_force_homing) ? -1 : 1;
        return 0;
    }
    if (!strcasecmp(sec, "LCM"))
        return lcm_key(&c->lcm, k, v);
    if (!strncasecmp(sec, "AXIS_", 5) && strlen(sec) == 6) {
        const char *p = strchr("XYZ", sec[5] & ~0x20);
        if (!p || !*p)
            return -2;
        return axis_key(&c->axis[p - "XYZ"], k, v);
    }
    if (!strcasecmp(sec, "PLANNER"))
        return planner_key(c, k, v);
    if (!strcasecmp(sec, "SIM")) {
        int r = sim_key(c, k, v);
        return r ? r : ncp_io_cfg_key(&c->io, sec, k, v, why, len);
    }
    if (!strcasecmp(sec, "RT"))
        return rt_key(c, k, v, why, len);
    if (!strcasecmp(sec, "CAN"))
        return can_key(&c->can, k, v);
    return ncp_io_cfg_key(&c->io, sec, k, v, why, len);
}

static int on_key(void *user, const char *sec, const char *k, const char *v)
{
    struct load_ctx *lc = user;
    if (lc->failed)
        return 0;
    char why[96] = "";
    int r = dispatch(lc->c, sec, k, v, why, sizeof why);
    if (r == 1)
        return 1;
    lc->failed = 1;
    if (r == -2)
        snprintf(lc->d->msg, sizeof lc->d->msg, "%s: unknown section [%s]", lc->path, sec);
    else if (r == 0)
        snprintf(lc->d->msg, sizeof lc->d->msg, "%s: [%s] unknown key %s", lc->path, sec, k);
    else
        snprintf(lc->d->msg, sizeof lc->d->msg, "%s: [%s] %s: bad value '%s'%s%s%s", lc->path, sec,
                 k, v, why[0] ? " (" : "", why, why[0] ? ")" : "");
    return 0;
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

static int check_cfg(const struct ncp_machine_cfg *c, const char *path, struct ncp_diag *d)
{
    int ratio = ncp_machine_cfg_ipo_ratio(c);
    if (ratio == 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "%s: [TRAJ] PLANNING_PERIOD %.0f ns must be a whole multiple of "
                            "[EMCMOT] SERVO_PERIOD %.0f ns",
                            path, c->planning_period * 1e9, c->servo_period * 1e9);
    for (int i = 0; i < NCP_AXES; i++) {
        if (c->axis[i].min_limit >= c->axis[i].max_limit)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                "%s: [AXIS_%c] MIN_LIMIT must be below MAX_LIMIT", path,
                                "XYZ"[i]);
        for (int j = 0; j < i; j++)
            if (c->axis[i].node_id && c->axis[i].node_id == c->axis[j].node_id)
                return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                                    "%s: [AXIS_%c] NODE_ID %d is already the node of [AXIS_%c]",
                                    path, "XYZ"[i], c->axis[i].node_id, "XYZ"[j]);
    }
    if (c->can.heartbeat_timeout_ms <= c->can.heartbeat_period_ms)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "%s: [CAN] HEARTBEAT_TIMEOUT_MS %d must be longer than "
                            "HEARTBEAT_PERIOD_MS %d",
                            path, c->can.heartbeat_timeout_ms, c->can.heartbeat_period_ms);
    /* a late planner thread makes the position loop slow down along the path
     * on what is left in the ring (src/rt/nck.c): half a stop from the top
     * speed at half the weakest axis's acceleration has to fit */
    double a_min = c->axis[0].max_acc;
    for (int i = 1; i < NCP_AXES; i++)
        a_min = fmin(a_min, c->axis[i].max_acc);
    double need = c->max_linear_vel / (a_min * c->servo_period) / ratio + 8;
    if ((double)c->setpoint_ring < need)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "%s: [PLANNER] SETPOINT_RING %d is too small to stop along the path "
                            "from MAX_LINEAR_VELOCITY: at least %.0f planning periods",
                            path, c->setpoint_ring, ceil(need));
    return NCP_OK;
}

int ncp_machine_cfg_load(struct ncp_machine_cfg *c, const char *path, struct ncp_diag *d)
{
    memset(d, 0, sizeof *d);
    struct load_ctx lc = { c, path, d, 0 };
    FILE *f = fopen(path, "r");
    if (!f)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: cannot open: %s", path, strerror(errno));
    int r = ini_parse_file(f, on_key, &lc);
    fclose(f);
    if (r != 0) {
        d->code = NCP_ERR_SEMANTIC;
        d->line = r > 0 ? (uint32_t)r : 0;
        if (!lc.failed)
            snprintf(d->msg, sizeof d->msg, "%s: malformed line", path);
        return d->code;
    }
    return check_cfg(c, path, d);
}
