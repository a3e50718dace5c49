/* [KINS] (which kinematics, LinuxCNC's module names, and their pivot
 * offsets under the names of its HAL pins) and [JOINT_n] (the limits of
 * what each servo drives, LinuxCNC's keys). */
#include "kins_cfg.h"
#include "ini_num.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

enum { JK_MIN_LIMIT, JK_MAX_LIMIT, JK_MAX_VELOCITY, JK_MAX_ACCELERATION, JK_FERROR };

int ncp_kins_joint_section(const char *sec)
{
    if (strncasecmp(sec, "JOINT_", 6) != 0 || strlen(sec) != 7 || sec[6] < '0' || sec[6] > '8')
        return -1;
    return sec[6] - '0';
}

static int number(const char *v, double lo, double hi, double *out, const char *unit,
                  char *why, size_t len)
{
    if (ncp_ini_number(v, lo, hi, out) == 0)
        return 1;
    snprintf(why, len, "%s from %g to %g", unit, lo, hi);
    return -1;
}

/* X_ROT_POINT, x-rot-point, ... -> the same spelling */
static int pin_name(const char *k, const char *want)
{
    for (; *k && *want; k++, want++) {
        char a = *k == '-' ? '_' : (char)(*k & ~0x20);
        if (a != *want)
            return 0;
    }
    return *k == *want;
}

static int kins_key(struct kins_load *kl, struct ncp_machine_cfg *c, const char *k,
                    const char *v, unsigned line, char *why, size_t len)
{
    if (!strcasecmp(k, "KINEMATICS")) {
        /* LinuxCNC writes the module's name, maybe with its parameters
         * (`trivkins coordinates=xyz`): only the name says the transform */
        char name[32];
        size_t n = strcspn(v, " \t");
        int t = n < sizeof name ? (memcpy(name, v, n), name[n] = '\0', ncp_kins_parse(name)) : -1;
        if (t < 0)
            return snprintf(why, len, "trivkins, xyzac-trt or xyzbc-trt"), -1;
        c->kins.type = t;
        kl->kins_line = line;
        return 1;
    }
    static const char *const rot[3] = { "X_ROT_POINT", "Y_ROT_POINT", "Z_ROT_POINT" };
    static const char *const off[3] = { "X_OFFSET", "Y_OFFSET", "Z_OFFSET" };
    for (int i = 0; i < 3; i++) {
        if (pin_name(k, rot[i]))
            return number(v, -1e6, 1e6, &c->kins.rot_point[i], "mm", why, len);
        if (pin_name(k, off[i])) {
            kl->offset_line[i] = line;
            return number(v, -1e6, 1e6, &c->kins.offset[i], "mm", why, len);
        }
    }
    return 0;
}

int ncp_kins_cfg_key(struct kins_load *kl, struct ncp_machine_cfg *c, const char *sec,
                     const char *k, const char *v, unsigned line, char *why, size_t len)
{
    if (!strcasecmp(sec, "KINS"))
        return kins_key(kl, c, k, v, line, why, len);
    int n = ncp_kins_joint_section(sec);
    if (n < 0)
        return -2;
    struct ncp_joint_cfg *j = &kl->raw[n];
    const struct { const char *name; double *dst; double lo, hi; const char *unit; } keys[] = {
        { "MIN_LIMIT", &j->min_limit, -1e6, 1e6, "mm (deg)" },
        { "MAX_LIMIT", &j->max_limit, -1e6, 1e6, "mm (deg)" },
        { "MAX_VELOCITY", &j->max_vel, 1e-6, 1e6, "mm/s (deg/s)" },
        { "MAX_ACCELERATION", &j->max_acc, 1e-6, 1e8, "mm/s^2 (deg/s^2)" },
        { "FERROR", &j->ferror, 1e-9, 1e6, "mm (deg)" },
    };
    kl->line[n] = kl->line[n] ? kl->line[n] : line;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcasecmp(k, keys[i].name) != 0)
            continue;
        kl->set[n] |= 1u << i;
        return number(v, keys[i].lo, keys[i].hi, keys[i].dst, keys[i].unit, why, len);
    }
    return 0;
}

void ncp_machine_joints_from_axes(struct ncp_machine_cfg *c)
{
    for (int i = 0; i < NCP_AXES; i++) {
        const struct ncp_axis_cfg *a = &c->axis[i];
        c->joint[i] = (struct ncp_joint_cfg){ a->min_limit, a->max_limit, a->max_vel, a->max_acc,
                                              a->ferror };
    }
}

/* The axes a transform turns or moves: it needs them all. */
static const char *required(int type)
{
    return type == NCP_KINS_XYZAC_TRT ? "XYZAC" : type == NCP_KINS_XYZBC_TRT ? "XYZBC" : "";
}

int ncp_kins_cfg_finish(struct kins_load *kl, struct ncp_machine_cfg *c, const char *coords,
                        char *msg, size_t len, unsigned *line)
{
    const char *name = ncp_kins_name(c->kins.type);
    for (const char *r = required(c->kins.type); *r; r++) {
        if (c->axis_mask & NCP_AXIS_BIT(strchr(NCP_AXIS_LETTERS, *r) - NCP_AXIS_LETTERS))
            continue;
        *line = kl->kins_line;
        snprintf(msg, len, "[KINS] KINEMATICS = %s needs the axes %s, and [TRAJ] COORDINATES "
                           "= %s lacks %c", name, required(c->kins.type), coords, *r);
        return -1;
    }
    /* the offset a module has no use for would be silently ignored */
    int unused = c->kins.type == NCP_KINS_XYZAC_TRT ? 0 : c->kins.type == NCP_KINS_XYZBC_TRT ? 1 : -1;
    for (int i = 0; i < 3; i++) {
        if (!kl->offset_line[i] || (unused >= 0 && i != unused))
            continue;
        *line = kl->offset_line[i];
        snprintf(msg, len, "[KINS] %c_OFFSET: %s has no use for it (%s)", "XYZ"[i], name,
                 unused < 0 ? "trivial kinematics have no pivots"
                 : unused == 0 ? "its A pivot is offset in Y and Z only"
                               : "its B pivot is offset in X and Z only");
        return -1;
    }
    ncp_machine_joints_from_axes(c);
    for (int n = 0; n < NCP_AXES && c->kins.type == NCP_KINS_TRIVIAL; n++) {
        if (!kl->line[n])
            continue;
        *line = kl->line[n];
        snprintf(msg, len, "[JOINT_%d]: under trivkins each joint is its axis, limited by its "
                           "[AXIS_L] section; joints of their own come with [KINS] KINEMATICS "
                           "= xyzac-trt or xyzbc-trt", n);
        return -1;
    }
    size_t nj = strlen(coords);
    for (int n = 0; n < NCP_AXES; n++) {
        if (!kl->line[n])
            continue;
        if ((size_t)n >= nj) {
            *line = kl->line[n];
            snprintf(msg, len, "[JOINT_%d] is for a joint [TRAJ] COORDINATES = %s does not "
                               "have (joints count from 0 in its order)", n, coords);
            return -1;
        }
        int ax = (int)(strchr(NCP_AXIS_LETTERS, coords[n]) - NCP_AXIS_LETTERS);
        struct ncp_joint_cfg *j = &c->joint[ax];
        const struct ncp_joint_cfg *r = &kl->raw[n];
        if (kl->set[n] & (1u << JK_MIN_LIMIT))
            j->min_limit = r->min_limit;
        if (kl->set[n] & (1u << JK_MAX_LIMIT))
            j->max_limit = r->max_limit;
        if (kl->set[n] & (1u << JK_MAX_VELOCITY))
            j->max_vel = r->max_vel;
        if (kl->set[n] & (1u << JK_MAX_ACCELERATION))
            j->max_acc = r->max_acc;
        if (kl->set[n] & (1u << JK_FERROR))
            j->ferror = r->ferror;
        if (j->min_limit >= j->max_limit) {
            *line = kl->line[n];
            snprintf(msg, len, "[JOINT_%d] (%c) MIN_LIMIT must be below MAX_LIMIT", n, coords[n]);
            return -1;
        }
    }
    return 0;
}
