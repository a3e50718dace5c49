/* The INI keys of what an operator sets and may set: where the offsets and
 * tool data persist ([RS274NGC] PARAMETER_FILE, [EMCIO] TOOL_TABLE) and how
 * far the overrides go ([DISPLAY] MAX_FEED_OVERRIDE, MIN_SPINDLE_OVERRIDE,
 * MAX_SPINDLE_OVERRIDE), under LinuxCNC's names and meanings. Without
 * them the feed override stops at 100 % (AXIS's default), so motion at 100 %
 * is as fast as the limits allow (see MAX_FEED_OVERRIDE in ini_keys.c). */
#include "ncpar/config.h"
#include "ini_num.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

void ncp_op_cfg_default(struct ncp_op_cfg *op)
{
    memset(op, 0, sizeof *op);
    op->max_feed_override = 1.0;
    op->min_spindle_override = 0.0;
    op->max_spindle_override = 2.0;   /* the 0..200 % cnc-ctl always took */
}

/* LinuxCNC opens a relative file from the configuration's folder (it runs
 * there); so does ncpar, whatever folder it was started in. */
static int path_key(char *dst, size_t cap, const char *ini_path, const char *v, char *why,
                    size_t len)
{
    const char *slash = strrchr(ini_path, '/');
    int base = v[0] == '/' || !slash ? 0 : (int)(slash - ini_path) + 1;
    size_t n = strlen(v);
    if (n == 0 || (size_t)base + n >= cap)
        return snprintf(why, len, "a path of 1 to %zu characters", cap - 1 - (size_t)base), -1;
    snprintf(dst, cap, "%.*s%s", base, ini_path, v);
    return 1;
}

static int ratio(const char *v, double lo, double hi, double *out, char *why, size_t len)
{
    if (ncp_ini_number(v, lo, hi, out) == 0)
        return 1;
    snprintf(why, len, "a ratio from %g to %g, 1.0 = 100 %%", lo, hi);
    return -1;
}

int ncp_op_cfg_key(struct ncp_op_cfg *op, const char *ini_path, const char *sec, const char *k,
                   const char *v, char *why, size_t len)
{
    if (!strcasecmp(sec, "RS274NGC"))
        return strcasecmp(k, "PARAMETER_FILE") ? 0
               : path_key(op->parameter_file, sizeof op->parameter_file, ini_path, v, why, len);
    if (!strcasecmp(sec, "EMCIO") && !strcasecmp(k, "TOOL_TABLE"))
        return path_key(op->tool_table, sizeof op->tool_table, ini_path, v, why, len);
    if (strcasecmp(sec, "DISPLAY") != 0)
        return -2;
    /* 2.0: what the position loop's time scaling takes (ncpar/nck.h) */
    if (!strcasecmp(k, "MAX_FEED_OVERRIDE"))
        return ratio(v, 1.0, 2.0, &op->max_feed_override, why, len);
    if (!strcasecmp(k, "MAX_SPINDLE_OVERRIDE"))
        return ratio(v, 0.0, 2.0, &op->max_spindle_override, why, len);
    if (!strcasecmp(k, "MIN_SPINDLE_OVERRIDE"))
        return ratio(v, 0.0, 2.0, &op->min_spindle_override, why, len);
    if (!strcasecmp(k, "HISTORY_FILE")) {
        op->history_given = 1;
        if (!strcasecmp(v, "NONE"))
            return op->history_file[0] = 0, 1;
        return path_key(op->history_file, sizeof op->history_file, ini_path, v, why, len);
    }
    return 0;
}

int ncp_op_cfg_check(const struct ncp_op_cfg *op, char *why, size_t len)
{
    if (op->min_spindle_override > op->max_spindle_override)
        return snprintf(why, len, "[DISPLAY] MIN_SPINDLE_OVERRIDE %g is above "
                        "MAX_SPINDLE_OVERRIDE %g", op->min_spindle_override,
                        op->max_spindle_override), -1;
    return 0;
}
