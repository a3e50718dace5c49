/* Conversions between the frames rs274 itself works in. A coordinate system
 * may be rotated about Z (G10 L2 R): machine = rot(program + G92) + origin +
 * tool offset, the rotation acting on X/Y only. Plain moves stay in program
 * coordinates (the canon rotates them later), but G53, G28/G30, G10, G43,
 * coordinate system changes and #<_abs_*> convert through the rotation. Each
 * helper keeps rs274's order of floating-point operations, even with no
 * rotation, so that the results agree to the last bit. Also the unit
 * conversions between the program's unit and rs274's user unit (inch). */
#include "stages.h"

#include <math.h>

/* rs274 -g converts through mm with its canon's inch-per-mm constant, which is
 * not exactly 1/25.4: these keep its rounding (2 mm -> user unit -> mm is 2.0
 * there, 1.9999999999999998 with a plain 25.4). */
#define NCP_USER_PER_MM 0.03937007874016

double ncp_user_len(const struct ncp_analyzer *a, double user)
{
    double mm = user / NCP_USER_PER_MM;
    return a->st.m.inches ? mm / NCP_MM_PER_INCH : mm;
}

/* Tool table values are user-unit lengths like any other. */
double ncp_tool_len(const struct ncp_analyzer *a, double user)
{
    return ncp_user_len(a, user);
}

double ncp_to_user_len(const struct ncp_analyzer *a, double prog)
{
    return (a->st.m.inches ? prog * NCP_MM_PER_INCH : prog) * NCP_USER_PER_MM;
}

void ncp_rotate(double *x, double *y, double deg)
{
    double t = deg * (M_PI / 180.0);
    double c = cos(t), s = sin(t);
    double xx = *x * c - *y * s;
    double yy = *x * s + *y * c;
    *x = xx;
    *y = yy;
}

static int ncp_axis_linear(int ax)
{
    return ax < NCP_A || ax > NCP_C;
}

double ncp_frame_param(const struct ncp_analyzer *a, int index)
{
    const double *p = ncp_params_slot(a->params, index);
    return p ? *p : 0.0;
}

/* A stored (user unit) parameter of axis `ax` in program units. */
double ncp_frame_user(const struct ncp_analyzer *a, int ax, int index)
{
    double v = ncp_frame_param(a, index);
    return ncp_axis_linear(ax) ? ncp_user_len(a, v) : v;
}

/* The current point as it would read in coordinate system `sys` (1..9),
 * G92 taken from its parameters when they are applied (#5210). With
 * `with_tlo` the tool offset is added back (the point as if no tool offset
 * were in effect), as G10 L10/L11 need. */
void ncp_frame_current_in(const struct ncp_analyzer *a, int sys, int with_tlo, double *out)
{
    const struct ncp_state *s = &a->st;
    for (int ax = 0; ax < NCP_NAX; ax++)
        out[ax] = s->pos[ax] + s->g92[ax];
    ncp_rotate(&out[NCP_X], &out[NCP_Y], s->rotation);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        out[ax] += s->g5x[ax];
        if (with_tlo)
            out[ax] += s->tlo[ax];
        out[ax] -= ncp_frame_user(a, ax, 5201 + 20 * sys + ax);
    }
    ncp_rotate(&out[NCP_X], &out[NCP_Y], -ncp_frame_param(a, 5210 + 20 * sys));
    if (ncp_frame_param(a, 5210) != 0.0)
        for (int ax = 0; ax < NCP_NAX; ax++)
            out[ax] -= ncp_frame_user(a, ax, 5211 + ax);
}

/* A machine point in the active system's program coordinates (G28/G30). */
void ncp_frame_relative(const struct ncp_analyzer *a, const double *abs, double *out)
{
    const struct ncp_state *s = &a->st;
    out[NCP_X] = abs[NCP_X] - s->g5x[NCP_X] - s->tlo[NCP_X];
    out[NCP_Y] = abs[NCP_Y] - s->g5x[NCP_Y] - s->tlo[NCP_Y];
    ncp_rotate(&out[NCP_X], &out[NCP_Y], -s->rotation);
    out[NCP_X] -= s->g92[NCP_X];
    out[NCP_Y] -= s->g92[NCP_Y];
    for (int ax = NCP_Z; ax < NCP_NAX; ax++) {
        out[ax] = abs[ax] - s->g5x[ax] - s->g92[ax];
        if (ncp_axis_linear(ax))
            out[ax] -= s->tlo[ax];
    }
}

/* The current point in machine coordinates (#<_abs_x>.., G28.1/G30.1). */
void ncp_frame_absolute(const struct ncp_analyzer *a, double *out)
{
    ncp_frame_absolute_of(a, a->st.pos, out);
}

/* The same for any point `pos` of the active system. */
void ncp_frame_absolute_of(const struct ncp_analyzer *a, const double *pos, double *out)
{
    const struct ncp_state *s = &a->st;
    double x = pos[NCP_X] + s->g92[NCP_X], y = pos[NCP_Y] + s->g92[NCP_Y];
    ncp_rotate(&x, &y, s->rotation);
    out[NCP_X] = x + s->g5x[NCP_X] + s->tlo[NCP_X];
    out[NCP_Y] = y + s->g5x[NCP_Y] + s->tlo[NCP_Y];
    for (int ax = NCP_Z; ax < NCP_NAX; ax++)
        out[ax] = pos[ax] + s->g92[ax] + s->g5x[ax] + s->tlo[ax];
}

/* The G53 end point: given axes are machine coordinates, the others keep
 * the current point; X/Y go through the rotation together. */
void ncp_frame_g53(const struct ncp_analyzer *a, const double *word, uint32_t given, double *end)
{
    const struct ncp_state *s = &a->st;
    double cx = s->pos[NCP_X] + s->g92[NCP_X], cy = s->pos[NCP_Y] + s->g92[NCP_Y];
    ncp_rotate(&cx, &cy, s->rotation);
    end[NCP_X] = (given >> NCP_X) & 1u ? word[NCP_X] - s->g5x[NCP_X] - s->tlo[NCP_X] : cx;
    end[NCP_Y] = (given >> NCP_Y) & 1u ? word[NCP_Y] - s->g5x[NCP_Y] - s->tlo[NCP_Y] : cy;
    ncp_rotate(&end[NCP_X], &end[NCP_Y], -s->rotation);
    end[NCP_X] -= s->g92[NCP_X];
    end[NCP_Y] -= s->g92[NCP_Y];
    for (int ax = NCP_Z; ax < NCP_NAX; ax++) {
        if (!((given >> ax) & 1u)) {
            end[ax] = s->pos[ax];
            continue;
        }
        end[ax] = word[ax] - s->g5x[ax] - s->g92[ax];
        if (ncp_axis_linear(ax))
            end[ax] -= s->tlo[ax];
    }
}
