/* The drive's own homing mode (CiA 402, 0x6060 = 6) as the simulated drive
 * does it. The home switch is a "positive" one: pressed at and above
 * --home-switch on the encoder's counts. Methods:
 *   35, 37  the current position is home;
 *   19, 20  home is the switch's edge, reached moving negative from the
 *           pressed side (19) or positive from the released side (20);
 *   3, 4    home is the first index pulse (every --index-pitch counts) past
 *           that edge, in the same direction (3 negative, 4 positive).
 * The axis first seeks the side of the switch the method starts from at
 * 0x6099:01, then latches at 0x6099:02, accelerating at 0x609A, one step
 * per SYNC: a homing takes the time it would on a machine. At home the
 * drive's position becomes the home offset 0x607C; it then brakes to rest
 * and reports homing attained (statusword bit 12) with target reached (bit
 * 10). Any other method, or a switch or index the method needs and the
 * drive was not given, is a homing error (bit 13). Bit 4 going down
 * interrupts the homing: the axis brakes, nothing attained.
 * For the master's failure paths: --homing-error MS ends the first homing
 * MS ms in with a homing error (the axis stops where it is; later homings
 * succeed, the fault fixed), --homing-stall
 * has the search never see the switch, so the axis searches on and no
 * homing is ever attained. */
#include <math.h>
#include <stdio.h>

#include "drive.h"

static double encoder(const struct drive *dv, double pos)
{
    return pos - dv->home.ref;
}

static int pressed_at(const struct drive *dv, double enc)
{
    return dv->o.have_home_switch && enc >= dv->o.home_switch;
}

int drive_home_switch(const struct drive *dv)
{
    return pressed_at(dv, encoder(dv, dv->actual));
}

uint16_t drive_home_statusword(const struct drive *dv)
{
    const struct drive_homing *h = &dv->home;
    uint16_t sw = 0;
    if (h->stage == DH_IDLE)
        sw |= NCP_402_SW_TARGET_REACHED;
    if (h->attained)
        sw |= NCP_402_SW_HOMING_ATTAINED;
    if (h->error)
        sw |= NCP_402_SW_HOMING_ERROR;
    return sw;
}

static int method(struct drive *dv)
{
    return (int8_t)(od_get(&dv->od, 0x6098, 0) & 0xFFu);
}

/* The position here is home: from now on the drive counts from 0x607C. */
static void set_home(struct drive *dv, double home_enc)
{
    struct drive_homing *h = &dv->home;
    int32_t ref = (int32_t)od_get(&dv->od, 0x607C, 0) - (int32_t)lround(home_enc);
    h->pos += ref - h->ref;
    h->ref = ref;
    h->found = 1;
    if (dv->o.verbose)
        fprintf(stderr, "cnc-drive-sim node %u: homing method %d: home at encoder count %ld, "
                        "position %d there (0x607C)\n",
                dv->o.node, method(dv), lround(home_enc), (int32_t)od_get(&dv->od, 0x607C, 0));
}

static void refuse(struct drive *dv, const char *why)
{
    dv->home.error = 1;
    dv->home.stage = DH_IDLE;
    if (dv->o.verbose)
        fprintf(stderr, "cnc-drive-sim node %u: homing error: %s\n", dv->o.node, why);
}

static void begin(struct drive *dv)
{
    struct drive_homing *h = &dv->home;
    int m = method(dv);
    h->attained = h->error = h->found = 0;
    h->pos = dv->actual;
    h->v = 0;
    h->elapsed = 0;
    if (m == 35 || m == 37) {
        set_home(dv, encoder(dv, h->pos));
        dv->actual = (int32_t)lround(h->pos);
        h->attained = 1;
        h->stage = DH_IDLE;
        return;
    }
    const char *why = m != 3 && m != 4 && m != 19 && m != 20
                          ? "method not implemented (3, 4, 19, 20, 35 and 37 are)"
                      : !dv->o.have_home_switch ? "the method needs a home switch (--home-switch)"
                      : (m == 3 || m == 4) && dv->o.index_pitch <= 0
                          ? "the method needs an index pulse (--index-pitch)"
                          : NULL;
    if (why) {
        refuse(dv, why);
        return;
    }
    /* 3 and 19 latch moving negative off the pressed side, 4 and 20
     * positive onto it from the released side */
    h->dir = (m == 3 || m == 19) ? -1 : 1;
    h->stage = DH_SEEK;
}

void drive_home_control(struct drive *dv, uint16_t cw, uint16_t prev_cw)
{
    struct drive_homing *h = &dv->home;
    if (!h->mode6 || dv->st != NCP_402_OPERATION_ENABLED)
        return;
    int up = (cw & NCP_402_CW_HOMING_START) != 0, was = (prev_cw & NCP_402_CW_HOMING_START) != 0;
    if (up && !was) {
        begin(dv);
    } else if (!up && was && h->stage != DH_IDLE && h->stage != DH_BRAKE) {
        h->found = 0;
        h->stage = DH_BRAKE;
    }
}

void drive_home_halt(struct drive *dv)
{
    struct drive_homing *h = &dv->home;
    if (h->stage != DH_IDLE)
        h->attained = h->found = 0;
    h->stage = DH_IDLE;
    h->v = 0;
}

void drive_home_mode(struct drive *dv, uint32_t mode)
{
    int was = dv->home.mode6;
    dv->home.mode6 = mode == 6;
    if (was && !dv->home.mode6)
        drive_home_halt(dv);
}

static double param(struct drive *dv, uint16_t index, uint8_t sub)
{
    return od_get(&dv->od, index, sub);
}

int32_t drive_home_step(struct drive *dv)
{
    struct drive_homing *h = &dv->home;
    if (h->stage == DH_IDLE)
        return dv->actual;
    double t = drive_period_s(dv), dvmax = param(dv, 0x609A, 0) * t;
    h->elapsed += t;
    if (dv->o.homing_error_ms > 0 && !dv->homing_error_given &&
        h->elapsed * 1000 >= (double)dv->o.homing_error_ms) {
        dv->homing_error_given = 1;
        refuse(dv, "--homing-error");
        h->v = 0;
        return (int32_t)lround(h->pos);
    }
    double want = 0;
    int wanted_pressed = h->dir < 0;
    switch (h->stage) {
    case DH_SEEK: want = -h->dir * param(dv, 0x6099, 1); break;
    case DH_LATCH:
    case DH_INDEX: want = h->dir * param(dv, 0x6099, 2); break;
    default: break;
    }
    h->v = fmin(fmax(want, h->v - dvmax), h->v + dvmax);
    double before = encoder(dv, h->pos);
    h->pos += h->v * t;
    double now = encoder(dv, h->pos);
    int on = !dv->o.homing_stall && pressed_at(dv, now);
    switch (h->stage) {
    case DH_SEEK:
        if (on == wanted_pressed)
            h->stage = DH_LATCH;
        break;
    case DH_LATCH:
        if (on != wanted_pressed && h->v * h->dir > 0) {
            if (method(dv) == 19 || method(dv) == 20) {
                set_home(dv, dv->o.home_switch);
                h->stage = DH_BRAKE;
            } else {
                h->stage = DH_INDEX;
            }
        }
        break;
    case DH_INDEX: {
        /* the first multiple of the pitch crossed in the latch's direction */
        double p = dv->o.index_pitch;
        double k = h->dir > 0 ? floor(now / p) : ceil(now / p);
        if ((h->dir > 0 && k * p > before) || (h->dir < 0 && k * p < before)) {
            set_home(dv, k * p);
            h->stage = DH_BRAKE;
        }
        break;
    }
    case DH_BRAKE:
        if (h->v == 0) {
            h->stage = DH_IDLE;
            h->attained = h->found;
            if (dv->o.verbose)
                fprintf(stderr, "cnc-drive-sim node %u: homing %s at position %ld\n",
                        dv->o.node, h->found ? "attained" : "interrupted", lround(h->pos));
        }
        break;
    default: break;
    }
    return (int32_t)lround(h->pos);
}
