/* The INI keys of the machine functions around the axes: the simulated
 * spindle ([SPINDLE_0]), the tool changer ([EMCIO], LinuxCNC's keys) and the
 * simulated inputs and pause behaviour of a batch run ([SIM]). Every key is
 * optional: a machine file written before these existed keeps its meaning. */
#include "ncpar/config.h"
#include "ini_num.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void ncp_io_cfg_default(struct ncp_io_cfg *io)
{
    memset(io, 0, sizeof *io);
    io->spindle_max_rpm = NCP_SPINDLE_TOP_RPM;
    io->orient_rpm = 60.0;
    io->at_speed_tol = 0.01;
}

/* 1 taken, -1 bad value: what a key reader returns */
static int number(const char *v, double lo, double hi, double *out)
{
    return ncp_ini_number(v, lo, hi, out) == 0 ? 1 : -1;
}

/* <prefix><n> with n in 0..max-1: n, or -1 */
static int indexed(const char *k, const char *prefix, int max)
{
    size_t n = strlen(prefix);
    if (strncasecmp(k, prefix, n) != 0 || !k[n])
        return -1;
    char *end;
    long i = strtol(k + n, &end, 10);
    return *end || i < 0 || i >= max ? -1 : (int)i;
}

static int spindle_key(struct ncp_io_cfg *io, const char *k, const char *v)
{
    if (!strcasecmp(k, "MAX_RPM")) {
        /* 0 once meant no cap: no spindle turns at any speed */
        int rc = number(v, 0, NCP_SPINDLE_TOP_RPM, &io->spindle_max_rpm);
        if (rc > 0 && io->spindle_max_rpm == 0)
            io->spindle_max_rpm = NCP_SPINDLE_TOP_RPM;
        return rc;
    }
    if (!strcasecmp(k, "MAX_ACCELERATION"))
        return number(v, 0, 1e9, &io->spindle_acc);
    if (!strcasecmp(k, "ORIENT_RPM"))
        return number(v, 1e-3, 1e5, &io->orient_rpm);
    if (!strcasecmp(k, "AT_SPEED_TOLERANCE"))
        return number(v, 1e-6, 1, &io->at_speed_tol);
    return 0;
}

static int emcio_key(struct ncp_io_cfg *io, const char *k, const char *v, char *why, size_t len)
{
    if (!strcasecmp(k, "TOOL_CHANGE_QUILL_UP")) {
        double x;
        if (number(v, 0, 1, &x) < 0 || (x != 0 && x != 1))
            return -1;
        io->quill_up = x != 0;
        return 1;
    }
    if (!strcasecmp(k, "TOOL_CHANGE_POSITION")) {
        double p[3];
        int n = 0;
        char extra;
        n = sscanf(v, "%lf %lf %lf %c", &p[0], &p[1], &p[2], &extra);
        if (n != 3 || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
            snprintf(why, len, "X Y Z in machine coordinates, mm");
            return -1;
        }
        memcpy(io->tc_pos, p, sizeof p);
        io->have_tc_pos = 1;
        return 1;
    }
    /* LinuxCNC's other [EMCIO] keys (cycle time, random
     * changer) are the interpreter's or the tool table's business */
    if (!strcasecmp(k, "CYCLE_TIME") ||
        !strcasecmp(k, "EMCIO") || !strcasecmp(k, "RANDOM_TOOLCHANGER") ||
        !strcasecmp(k, "TOOL_CHANGE_WITH_SPINDLE_ON") || !strcasecmp(k, "TOOL_CHANGE_AT_G30"))
        return 1;
    return 0;
}

/* The simulated workpiece of the probe. */
static int probe_key(struct ncp_io_cfg *io, const char *k, const char *v, char *why, size_t len)
{
    if (!strcasecmp(k, "PROBE_PLANE_Z")) {
        if (number(v, -1e6, 1e6, &io->probe_plane_z) < 0)
            return -1;
        io->have_probe_plane = 1;
        return 1;
    }
    if (strcasecmp(k, "PROBE_BOX") != 0)
        return 0;
    /* six plain decimals, as every other number of the file */
    double b[6] = { 0 };
    char buf[256], *save = NULL;
    snprintf(buf, sizeof buf, "%s", v);
    int n = 0, ok = strlen(v) < sizeof buf;
    for (char *t = strtok_r(buf, " \t", &save); ok && t; t = strtok_r(NULL, " \t", &save))
        ok = n < 6 && number(t, -1e6, 1e6, &b[n++]) > 0;
    ok = ok && n == 6;
    for (int i = 0; ok && i < 3; i++)
        ok = isfinite(b[i]) && isfinite(b[i + 3]) && b[i] < b[i + 3];
    if (!ok) {
        snprintf(why, len, "xmin ymin zmin xmax ymax zmax in machine coordinates, mm, "
                           "each min below its max");
        return -1;
    }
    memcpy(io->probe_box, b, sizeof b);
    io->have_probe_box = 1;
    return 1;
}

static int sim_key(struct ncp_io_cfg *io, const char *k, const char *v)
{
    if (!strcasecmp(k, "AUTO_RESUME_S"))
        return number(v, -1, 1e6, &io->auto_resume_s);
    int i = indexed(k, "DIGITAL_IN_", NCP_DIO_MAX);
    if (i >= 0) {
        double x;
        if (number(v, 0, 1, &x) < 0 || (x != 0 && x != 1))
            return -1;
        if (x != 0)
            io->din |= 1ull << i;
        else
            io->din &= ~(1ull << i);
        return 1;
    }
    if ((i = indexed(k, "ANALOG_IN_", NCP_AIO_MAX)) >= 0)
        return number(v, -1e9, 1e9, &io->ain[i]);
    return 0;
}

int ncp_io_cfg_key(struct ncp_io_cfg *io, const char *sec, const char *k, const char *v,
                   char *why, size_t len)
{
    if (!strcasecmp(sec, "SPINDLE_0"))
        return spindle_key(io, k, v);
    if (!strcasecmp(sec, "EMCIO"))
        return emcio_key(io, k, v, why, len);
    if (!strcasecmp(sec, "SIM")) {
        int rc = probe_key(io, k, v, why, len);
        return rc ? rc : sim_key(io, k, v);
    }
    return -2;
}
