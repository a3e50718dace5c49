/* The machine INI's homing keys, as LinuxCNC names them: per axis in
 * [AXIS_L], and the simulated home switch's place in [SIM]. What they do
 * is src/nck/homing.c's. */
#include "ncpar/config.h"

#include "ini_num.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* LinuxCNC writes its switches as YES/NO as often as 1/0. */
static int flag(const char *v, int *out)
{
    static const char *const yes[] = { "1", "YES", "TRUE" }, *const no[] = { "0", "NO", "FALSE" };
    for (size_t i = 0; i < 3; i++) {
        if (!strcasecmp(v, yes[i]))
            return *out = 1, 0;
        if (!strcasecmp(v, no[i]))
            return *out = 0, 0;
    }
    return -1;
}

int ncp_home_cfg_key(struct ncp_axis_cfg *a, const char *k, const char *v, char *why,
                     size_t len)
{
    const struct { const char *name; double *dst; double lo, hi; const char *unit; } keys[] = {
        { "HOME", &a->home, -1e6, 1e6, "mm" },
        { "HOME_OFFSET", &a->home_offset, -1e6, 1e6, "mm" },
        { "HOME_SEARCH_VEL", &a->home_search_vel, -1e6, 1e6, "mm/s, signed; 0: no home switch" },
        { "HOME_LATCH_VEL", &a->home_latch_vel, -1e6, 1e6, "mm/s, signed" },
        { "HOME_FINAL_VEL", &a->home_final_vel, 0, 1e6, "mm/s; 0: MAX_VELOCITY" },
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcasecmp(k, keys[i].name) != 0)
            continue;
        if (ncp_ini_number(v, keys[i].lo, keys[i].hi, keys[i].dst) == 0)
            return 1;
        snprintf(why, len, "%s, %g to %g", keys[i].unit, keys[i].lo, keys[i].hi);
        return -1;
    }
    double x;
    if (!strcasecmp(k, "HOME_SEQUENCE")) {
        if (ncp_ini_number(v, -99, 99, &x) || x != floor(x))
            return snprintf(why, len, "a whole number from -99 to 99"), -1;
        a->home_sequence = (int)x;
        a->have_home_sequence = 1;
        return 1;
    }
    if (!strcasecmp(k, "HOME_METHOD")) {
        if (!strcasecmp(v, "nck"))
            return a->home_drive = 0, 1;
        if (strncasecmp(v, "drive:", 6) != 0 || ncp_ini_number(v + 6, -128, 127, &x) ||
            x != floor(x))
            return snprintf(why, len, "nck, or drive:N, N a CiA 402 homing method (0x6098) "
                                      "-128..127; cnc-drive-sim has 3, 4, 19, 20, 35, 37"), -1;
        a->home_drive = 1;
        a->home_method = (int)x;
        return 1;
    }
    if (!strcasecmp(k, "HOME_IGNORE_LIMITS"))
        return flag(v, &a->home_ignore_limits) ? snprintf(why, len, "0 or 1 (NO or YES)"), -1 : 1;
    if (!strcasecmp(k, "HOME_USE_INDEX")) {
        int on;
        if (flag(v, &on))
            return snprintf(why, len, "0 or 1 (NO or YES)"), -1;
        if (on)
            return snprintf(why, len, "the simulated machine has no encoder index to latch on; "
                                      "it homes on the switch alone: 0 or NO"), -1;
        return 1;
    }
    return 0;
}

int ncp_home_switch_key(struct ncp_machine_cfg *c, const char *k, const char *v, char *why,
                        size_t len)
{
    if (strncasecmp(k, "HOME_SWITCH_", 12) != 0 || strlen(k) != 13)
        return -2;
    const char *p = strchr(NCP_AXIS_LETTERS, k[12] & ~0x20);
    if (!p || !*p)
        return -2;
    struct ncp_axis_cfg *a = &c->axis[p - NCP_AXIS_LETTERS];
    if (ncp_ini_number(v, -1e6, 1e6, &a->home_switch))
        return snprintf(why, len, "mm, -1000000 to 1000000"), -1;
    a->have_home_switch = 1;
    return 1;
}

int ncp_home_cfg_check(const struct ncp_machine_cfg *c, int axis, char *why, size_t len)
{
    const struct ncp_axis_cfg *a = &c->axis[axis];
    double vs = fabs(a->home_search_vel), vl = fabs(a->home_latch_vel);
    /* the drive's own homing takes the speeds as they are, latch alone too */
    if (!a->home_drive && vs > 0 && vl == 0)
        return snprintf(why, len, "HOME_LATCH_VEL must not be 0 with a home switch "
                                  "(HOME_SEARCH_VEL %g): the switch is latched at it",
                        a->home_search_vel), -1;
    if (!a->home_drive && vs == 0 && vl > 0)
        return snprintf(why, len, "HOME_LATCH_VEL %g without HOME_SEARCH_VEL is LinuxCNC's "
                                  "index-only homing: the simulated machine has no encoder index",
                        a->home_latch_vel), -1;
    const char *fast = vs > a->max_vel ? "HOME_SEARCH_VEL"
                       : vl > a->max_vel ? "HOME_LATCH_VEL"
                       : a->home_final_vel > a->max_vel ? "HOME_FINAL_VEL" : NULL;
    if (fast)
        return snprintf(why, len, "%s is above MAX_VELOCITY %g", fast, a->max_vel), -1;
    if (!a->wrapped && (a->home < a->min_limit || a->home > a->max_limit))
        return snprintf(why, len, "HOME %g lies outside MIN_LIMIT %g .. MAX_LIMIT %g: the axis "
                                  "would end homing beyond its soft limits",
                        a->home, a->min_limit, a->max_limit), -1;
    return 0;
}
