/* One block in rs274's execution order: comment, feed mode, F, S, T, M codes
 * by group, then G codes by group, motion, and the stop codes last. Each step
 * is a small function; the order lives in ncp_an_steps only. */
#include "floor.h"
#include "offsets.h"
#include "stages.h"

#include <math.h>
#include <stdio.h>

#define W(a, c) ((a)->w.v[NCP_LETTER(c)])

static int ncp_step_feed_mode(struct ncp_analyzer *a, int g)
{
    static const char *const msg[] = {
        "interpreter: feed mode set to units per minute",
        "interpreter: feed mode set to inverse time",
        "interpreter: feed mode set to units per revolution",
    };
    int mode = g == NCP_G93 ? 1 : g == NCP_G94 ? 0 : 2;
    const char *m = msg[mode];
    size_t n = 0;
    while (m[n])
        n++;
    ncp_an_emit_text(a, NCP_C_COMMENT, m, n);
    a->st.m.feed_mode = mode;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_FEED_MODE);
    op->feed_mode.per_rev = mode == 2 ? 1 : 0;
    if (mode != 1) {
        a->st.feed = 0.0;
        ncp_an_emit(a, NCP_C_SET_FEED_RATE);
    }
    return NCP_OK;
}

static void ncp_step_comment_lit(struct ncp_analyzer *a, const char *m)
{
    size_t n = 0;
    while (m[n])
        n++;
    ncp_an_emit_text(a, NCP_C_COMMENT, m, n);
}

static int ncp_step_spindle(struct ncp_analyzer *a, int m)
{
    if (m >= NCP_M70)
        return ncp_m7x_run(a, m);
    if (m == NCP_M3) {
        ncp_an_emit(a, NCP_C_START_SPINDLE_CLOCKWISE);
        a->st.m.spindle_dir = 1;
    } else if (m == NCP_M4) {
        ncp_an_emit(a, NCP_C_START_SPINDLE_COUNTERCLOCKWISE);
        a->st.m.spindle_dir = -1;
    } else if (m == NCP_M5) {
        ncp_an_emit(a, NCP_C_STOP_SPINDLE_TURNING);
        a->st.m.spindle_dir = 0;
    } else {
        /* M19: the spindle counts as stopped; the orient call only with R or P */
        a->st.m.spindle_dir = 0;
        if (NCP_HAS(&a->w, 'R') || NCP_HAS(&a->w, 'P')) {
            struct ncp_canon *op = ncp_an_emit(a, NCP_C_ORIENT_SPINDLE);
            op->orient.angle = (NCP_HAS(&a->w, 'R') ? W(a, 'R') : 0.0) + a->cfg.orient_offset;
            op->orient.direction = NCP_HAS(&a->w, 'P') ? ncp_trunc_int_round(W(a, 'P')) : 0;
        }
        if (NCP_HAS(&a->w, 'Q')) { /* wait for the orientation, Q seconds at most */
            if (W(a, 'Q') <= 0.0)
                return ncp_an_error(a, a->w.col[NCP_LETTER('Q')],
                                    "Q word with M19 requires a value > 0");
            char buf[64];
            int n = snprintf(buf, sizeof buf, "SPINDLE.0.WAIT_ORIENT_COMPLETE(%.4f)", W(a, 'Q'));
            ncp_an_emit_text(a, NCP_C_RAW_TEXT, buf,
                             n > 0 && (size_t)n < sizeof buf ? (size_t)n : sizeof buf - 1);
        }
    }
    return NCP_OK;
}

static int ncp_step_coolant(struct ncp_analyzer *a, int m)
{
    if (m == NCP_M7) {
        ncp_an_emit(a, NCP_C_MIST_ON);
        a->st.m.mist = 1;
    } else if (m == NCP_M8) {
        ncp_an_emit(a, NCP_C_FLOOD_ON);
        a->st.m.flood = 1;
    } else {
        ncp_an_emit(a, NCP_C_MIST_OFF);
        ncp_an_emit(a, NCP_C_FLOOD_OFF);
        a->st.m.mist = a->st.m.flood = 0;
    }
    return NCP_OK;
}

static int ncp_step_override(struct ncp_analyzer *a, int m)
{
    int on = !NCP_HAS(&a->w, 'P') || W(a, 'P') != 0.0;
    switch (m) {
    case NCP_M48:
        ncp_an_emit(a, NCP_C_ENABLE_FEED_OVERRIDE);
        ncp_an_emit(a, NCP_C_ENABLE_SPEED_OVERRIDE);
        a->st.m.feed_override = a->st.m.speed_override = 1;
        break;
    case NCP_M49:
        ncp_an_emit(a, NCP_C_DISABLE_FEED_OVERRIDE);
        ncp_an_emit(a, NCP_C_DISABLE_SPEED_OVERRIDE);
        a->st.m.feed_override = a->st.m.speed_override = 0;
        break;
    case NCP_M50:
        ncp_an_emit(a, on ? NCP_C_ENABLE_FEED_OVERRIDE : NCP_C_DISABLE_FEED_OVERRIDE);
        a->st.m.feed_override = on;
        break;
    case NCP_M51:
        ncp_an_emit(a, on ? NCP_C_ENABLE_SPEED_OVERRIDE : NCP_C_DISABLE_SPEED_OVERRIDE);
        a->st.m.speed_override = on;
        break;
    case NCP_M52:
        ncp_an_emit(a, on ? NCP_C_ENABLE_ADAPTIVE_FEED : NCP_C_DISABLE_ADAPTIVE_FEED);
        a->st.m.adaptive = on;
        break;
    default:
        ncp_an_emit(a, on ? NCP_C_ENABLE_FEED_HOLD : NCP_C_DISABLE_FEED_HOLD);
        a->st.m.feed_hold = on;
        break;
    }
    return NCP_OK;
}

/* M66: wait for a digital (P) or analog (E) input, L the wait type, Q the
 * timeout; rs274's checks in its order. There is no input here, as in
 * rs274 -g, whose stand-in returns the default: after a digital wait #5399
 * (the result) becomes 1 if it was not 0, else 0; after an analog one it
 * keeps its value. Nothing is printed (rs274 -g prints no call for it). On
 * the NCK the call goes to the machine and #5399 is read back from it. */
static int ncp_step_wait_input(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    uint16_t col = w->mcol[NCP_MG_IO];
    int has_p = NCP_HAS(w, 'P'), has_e = NCP_HAS(w, 'E'), has_l = NCP_HAS(w, 'L');
    double q = NCP_HAS(w, 'Q') ? W(a, 'Q') : -1.0;
    int l = has_l ? ncp_trunc_int_round(W(a, 'L')) : 0;
    if (has_p && has_e)
        return ncp_an_error(a, col, "Invalid to select both a digital and an analog input with M66");
    if (q <= 0.0 && has_l && l > 0)
        return ncp_an_error(a, col, "Zero timeout with wait type != immediate return");
    if (has_e && has_l && l != 0)
        return ncp_an_error(a, col, "Can't select analog input with wait type != immediate return");
    if ((has_p && ncp_trunc_int_round(W(a, 'P')) < 0) ||
        (has_e && ncp_trunc_int_round(W(a, 'E')) < 0) || (!has_p && !has_e))
        return ncp_an_error(a, col, "Need to have either a valid P or a valid E word with M66");
    if (a->st.m.comp_side != 0)
        return ncp_an_error(a, col, has_p ? "Cannot wait for digital input with cutter radius compensation on"
                                          : "Cannot wait for analog input with cutter radius compensation on");
    if (a->cfg.m66_on_machine) {
        struct ncp_canon *op = ncp_an_emit(a, NCP_C_WAIT_INPUT);
        op->wait_input.analog = !has_p;
        op->wait_input.index = ncp_trunc_int_round(has_p ? W(a, 'P') : W(a, 'E'));
        op->wait_input.mode = l;
        op->wait_input.timeout = q > 0 ? q : 0;
        /* the machine's result replaces the stand-in's at the next read
         * when the run has a machine to wait for (a queue buster) */
        a->sai.input_flag = 1;
    }
    if (has_p) {
        double *result = ncp_params_slot(a->params, 5399);
        *result = *result != 0.0 ? 1.0 : 0.0;
    }
    return NCP_OK;
}

static int ncp_step_io(struct ncp_analyzer *a, int m)
{
    static const enum ncp_canon_kind bits[] = {
        NCP_C_SET_MOTION_OUTPUT_BIT, NCP_C_CLEAR_MOTION_OUTPUT_BIT,
        NCP_C_SET_AUX_OUTPUT_BIT, NCP_C_CLEAR_AUX_OUTPUT_BIT,
    };
    if (m >= NCP_M62 && m <= NCP_M65) {
        if (!NCP_HAS(&a->w, 'P'))
            return ncp_an_error(a, a->w.mcol[NCP_MG_IO], "No valid P word with M%d", m);
        ncp_an_emit(a, bits[m - 62])->output.index = ncp_trunc_int_round(W(a, 'P'));
        return NCP_OK;
    }
    if (m == NCP_M67 || m == NCP_M68) {
        if (!NCP_HAS(&a->w, 'E') || lround(W(a, 'E')) < 0)
            return ncp_an_error(a, a->w.mcol[NCP_MG_IO], "Invalid analog index with M%d", m);
        struct ncp_canon *op = ncp_an_emit(a, m == NCP_M67 ? NCP_C_SET_MOTION_OUTPUT_VALUE
                                                      : NCP_C_SET_AUX_OUTPUT_VALUE);
        op->output.index = ncp_trunc_int_round(W(a, 'E'));
        op->output.value = NCP_HAS(&a->w, 'Q') ? W(a, 'Q') : -1.0;
        return NCP_OK;
    }
    if (m == NCP_M66)
        return ncp_step_wait_input(a);
    return ncp_an_error(a, a->w.mcol[NCP_MG_IO], "M%d is not supported", m);
}

static int ncp_step_plane(struct ncp_analyzer *a, int g)
{
    if (g != NCP_G17 && g != NCP_G18 && g != NCP_G19)
        return ncp_an_error(a, a->w.gcol[NCP_GG_PLANE], "G%d.1 planes are not supported", g / 10);
    int p = g == NCP_G17 ? 0 : g == NCP_G19 ? 1 : 2;
    ncp_an_emit(a, NCP_C_SELECT_PLANE)->plane.plane = p;
    a->st.m.plane = p;
    return NCP_OK;
}

static int ncp_step_comp(struct ncp_analyzer *a, int g)
{
    return ncp_comp_gcode(a, g);
}

static int ncp_step_control(struct ncp_analyzer *a, int g)
{
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_MOTION_CONTROL_MODE);
    /* the canon keeps the naivecam tolerance across G61/G61.1 */
    if (g == NCP_G61) {
        op->motion_control.mode = 1;
        a->st.m.control = 1;
        a->st.m.p_tol = 0.0;
    } else if (g == NCP_G61_1) {
        op->motion_control.mode = 0;
        a->st.m.control = 0;
        a->st.m.p_tol = 0.0;
    } else {
        /* rs274: a negative P or Q (P-1 is "no P") means the default, 0 here */
        double p_in = NCP_HAS(&a->w, 'P') ? W(a, 'P') : -1.0;
        double q_in = NCP_HAS(&a->w, 'Q') ? W(a, 'Q') : -1.0;
        double p = p_in >= 0 ? p_in : 0.0;
        double q = q_in >= 0 ? q_in : p;
        op->motion_control.mode = 2;
        op->motion_control.tolerance = p;
        a->st.m.control = 2;
        a->st.m.p_tol = p;
        a->st.m.q_tol = q;
        a->st.m.g64_p = p;
        a->st.m.g64_q = q;
        ncp_an_emit(a, NCP_C_SET_NAIVECAM_TOLERANCE)->naivecam.tolerance = q;
    }
    return NCP_OK;
}

static void ncp_step_distance(struct ncp_analyzer *a, int g)
{
    int inc = g == NCP_G91;
    if (inc != a->st.m.incremental)
        ncp_step_comment_lit(a, inc ? "interpreter: distance mode changed to incremental"
                                    : "interpreter: distance mode changed to absolute");
    a->st.m.incremental = inc;
}

static void ncp_step_arc_distance(struct ncp_analyzer *a, int g)
{
    int inc = g == NCP_G91_1;
    if (inc != a->st.m.arc_incremental)
        ncp_step_comment_lit(a, inc ? "interpreter: IJK distance mode changed to incremental"
                                    : "interpreter: IJK distance mode changed to absolute");
    a->st.m.arc_incremental = inc;
}

static void ncp_step_retract(struct ncp_analyzer *a, int g)
{
    a->st.m.retract_r = g == NCP_G99;
    ncp_step_comment_lit(a, g == NCP_G99 ? "interpreter: retract mode set to r_plane"
                                     : "interpreter: retract mode set to old_z");
}

/* The M codes of the block in rs274's order of groups: 5 (I/O), 6 (tool),
 * 7 (spindle, M70-M73), 8 (coolant), 9 (overrides), 10 (user); a remapped
 * code runs its remap in its group's turn (see ncp_m_step). */
static int ncp_m_group_run(struct ncp_analyzer *a, int slot)
{
    const struct ncp_words *w = &a->w;
    int m = w->m[slot];
    switch (slot) {
    case NCP_MG_IO: return ncp_step_io(a, m);
    case NCP_MG_TOOL: return ncp_tools_change(a);
    case NCP_MG_SPINDLE: return ncp_step_spindle(a, m);
    case NCP_MG_COOLANT: return ncp_step_coolant(a, m);
    case NCP_MG_OVERRIDE: return ncp_step_override(a, m);
    default:
        /* M100-M199 run the machine's programs of that name; rs274 -g has
         * none (its canon knows no user function), so it refuses them here,
         * after the block's other M codes, as does a machine without one */
        if (!ncp_user_m_has(a, m))
            return ncp_an_error(a, w->mcol[slot], "Unknown m code used: M%d", m);
        struct ncp_canon *op = ncp_an_emit(a, NCP_C_USER_M);
        op->user_m.code = m;
        op->user_m.col = w->mcol[slot];
        op->user_m.p = NCP_HAS(w, 'P') ? w->v[NCP_LETTER('P')] : -1.0;
        op->user_m.q = NCP_HAS(w, 'Q') ? w->v[NCP_LETTER('Q')] : -1.0;
        return NCP_OK;
    }
}

static int ncp_m_step(struct ncp_analyzer *a, int slot)
{
    if (a->w.m[slot] == -1)
        return NCP_OK;
    if (a->remaps) {
        int ran;
        int rc = ncp_remap_step(a, slot, &ran);
        if (ran || rc != NCP_OK)
            return rc;
    }
    return ncp_m_group_run(a, slot);
}

static int ncp_step_m_codes(struct ncp_analyzer *a)
{
    int rc = ncp_m_step(a, NCP_MG_IO);
    if (rc == NCP_OK)
        rc = ncp_m_step(a, NCP_MG_TOOL);
    if (rc == NCP_OK)
        rc = ncp_m_step(a, NCP_MG_SPINDLE);
    if (a->block_consumed) /* see ncp_an_steps */
        return rc;
    if (rc == NCP_OK)
        rc = ncp_m_step(a, NCP_MG_COOLANT);
    if (rc == NCP_OK)
        rc = ncp_m_step(a, NCP_MG_OVERRIDE);
    if (rc == NCP_OK)
        rc = ncp_m_step(a, NCP_MG_USER);
    return rc;
}

/* G7/G8. The block's X word was already scaled (analyzer.c, ncp_lathe_x_word);
 * rs274 says so only when the mode changes. */
static void ncp_step_lathe_mode(struct ncp_analyzer *a, int diameter)
{
    if (a->st.m.lathe_diameter == diameter)
        return;
    a->st.m.lathe_diameter = diameter;
    ncp_step_comment_lit(a, diameter ? "interpreter: Lathe diameter mode changed to diameter"
                                     : "interpreter: Lathe diameter mode changed to radius");
}

/* The block's motion (G code x10) to its handler. */
static int ncp_step_motion(struct ncp_analyzer *a, int motion)
{
    if (!ncp_is_canned_cycle(motion))
        a->st.cycle_il_flag = 0;
    switch (motion) {
    case NCP_G0: case NCP_G1:
        return ncp_motion_straight(a, motion);
    case NCP_G2: case NCP_G3:
        return ncp_motion_arc(a, motion);
    case NCP_G80:
        a->st.m.motion = NCP_G80;
        ncp_an_emit_text(a, NCP_C_COMMENT, "interpreter: motion mode set to none",
                         sizeof "interpreter: motion mode set to none" - 1);
        return NCP_OK;
    case NCP_G5: case NCP_G5_1:
        return ncp_motion_spline(a, motion);
    case NCP_G5_2:
        return ncp_g52_point(a);
    case NCP_G33: case NCP_G33_1: case NCP_G76:
        return ncp_motion_synced(a, motion);
    case NCP_G38_2: case NCP_G38_3: case NCP_G38_4: case NCP_G38_5:
        return ncp_motion_probe(a, motion);
    case NCP_G70: case NCP_G71: case NCP_G71_1: case NCP_G71_2:
    case NCP_G72: case NCP_G72_1: case NCP_G72_2:
        return ncp_g7x_run(a, motion);
    case NCP_G73: case NCP_G74: case NCP_G81: case NCP_G82: case NCP_G83: case NCP_G84:
    case NCP_G85: case NCP_G86: case NCP_G87: case NCP_G88: case NCP_G89:
        return ncp_canned_run(a, motion);
    default: {
        uint16_t col = NCP_MOTION_COL(&a->w);
        if (a->remaps) {
            int ran = 0;
            int rc = ncp_remap_g_step(a, motion, &ran);
            if (ran || rc != NCP_OK)
                return rc;
        }
        if (motion % 10)
            return ncp_an_error(a, col, "G%d.%d is not supported", motion / 10, motion % 10);
        return ncp_an_error(a, col, "G%d is not supported", motion / 10);
    }
    }
}

static int ncp_step_g_codes(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int rc = NCP_OK;
    if (w->g[NCP_GG_NONMODAL] == NCP_G4)
        ncp_an_emit(a, NCP_C_DWELL)->dwell.seconds = W(a, 'P');
    if (w->g[NCP_GG_PLANE] != -1)
        rc = ncp_step_plane(a, w->g[NCP_GG_PLANE]);
    if (rc == NCP_OK && w->g[NCP_GG_UNITS] != -1)
        rc = ncp_offsets_units(a, w->g[NCP_GG_UNITS] == NCP_G20);
    if (rc == NCP_OK && w->g[NCP_GG_LATHE] != -1)
        ncp_step_lathe_mode(a, w->g[NCP_GG_LATHE] == NCP_G7);
    if (rc == NCP_OK && w->g[NCP_GG_COMP] != -1)
        rc = ncp_step_comp(a, w->g[NCP_GG_COMP]);
    if (rc == NCP_OK && w->g[NCP_GG_TLO] != -1)
        rc = ncp_offsets_tlo(a, w->g[NCP_GG_TLO]);
    if (rc == NCP_OK && w->g[NCP_GG_COORD] != -1)
        rc = ncp_offsets_coord(a, 1 + (w->g[NCP_GG_COORD] >= NCP_G59
                                       ? 5 + w->g[NCP_GG_COORD] - 590
                                       : (w->g[NCP_GG_COORD] - 540) / 10));
    if (rc == NCP_OK && w->g[NCP_GG_CONTROL] != -1)
        rc = ncp_step_control(a, w->g[NCP_GG_CONTROL]);
    if (rc != NCP_OK)
        return rc;
    if (w->g[NCP_GG_DIST] != -1)
        ncp_step_distance(a, w->g[NCP_GG_DIST]);
    if (w->g[NCP_GG_ARCDIST] != -1)
        ncp_step_arc_distance(a, w->g[NCP_GG_ARCDIST]);
    if (w->g[NCP_GG_RETRACT] != -1)
        ncp_step_retract(a, w->g[NCP_GG_RETRACT]);
    if (w->g[NCP_GG_NONMODAL] == NCP_G5_3)
        rc = ncp_g52_draw(a);
    else if (w->g[NCP_GG_NONMODAL] != -1 && w->g[NCP_GG_NONMODAL] != NCP_G4 &&
             w->g[NCP_GG_NONMODAL] != NCP_G53)
        rc = ncp_offsets_modal0(a, w->g[NCP_GG_NONMODAL]);
    if (rc == NCP_OK && w->motion_to_be != -1)
        rc = ncp_step_motion(a, w->motion_to_be);
    return rc;
}

int ncp_an_steps(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int rc = NCP_OK;
    if (a->blk->comment_kind != NCP_CMT_NONE)
        rc = ncp_comment_run(a);
    if (rc == NCP_OK && w->g[NCP_GG_SPINDLE] != -1) {
        /* G96 without D: rs274 passes 1e30 as "no limit" */
        struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_SPINDLE_MODE);
        a->st.m.css = w->g[NCP_GG_SPINDLE] == NCP_G96;
        if (w->g[NCP_GG_SPINDLE] == NCP_G96)
            op->spindle_mode.css_max = NCP_HAS(w, 'D') ? W(a, 'D') : 1e30;
    }
    if (rc == NCP_OK && w->g[NCP_GG_FEEDMODE] != -1)
        rc = ncp_step_feed_mode(a, w->g[NCP_GG_FEEDMODE]);
    if (rc != NCP_OK)
        return rc;
    int ran = 0;
    if (NCP_HAS(w, 'F') && a->st.m.feed_mode != 1) {
        if (a->remaps)
            rc = ncp_remap_letter_step(a, 'F', &ran);
        if (rc != NCP_OK)
            return rc;
        if (!ran) {
            a->st.feed = W(a, 'F');
            ncp_an_emit(a, NCP_C_SET_FEED_RATE)->feed_rate.rate = a->st.feed;
        }
    }
    if (NCP_HAS(w, 'S')) {
        ran = 0;
        if (a->remaps)
            rc = ncp_remap_letter_step(a, 'S', &ran);
        if (rc != NCP_OK)
            return rc;
        if (!ran) {
            a->st.speed = W(a, 'S');
            ncp_an_emit(a, NCP_C_SET_SPINDLE_SPEED)->spindle_speed.speed = a->st.speed;
        }
    }
    if (NCP_HAS(w, 'T')) {
        ran = 0;
        if (a->remaps)
            rc = ncp_remap_letter_step(a, 'T', &ran);
        if (rc == NCP_OK && !ran)
            rc = ncp_tools_select(a);
    }
    if (rc == NCP_OK && w->n_m != 0) /* most blocks have none: skip the group tests */
        rc = ncp_step_m_codes(a);
    if (a->block_consumed) { /* M72's restore lines ran in this block's place */
        a->block_consumed = 0;
        ncp_offsets_sync_params(a);
        return rc;
    }
    if (rc == NCP_OK)
        rc = ncp_step_g_codes(a);
    if (rc == NCP_OK && w->m[NCP_MG_STOP] != -1) {
        ran = 0;
        if (a->remaps)
            rc = ncp_remap_step(a, NCP_MG_STOP, &ran);
        if (rc == NCP_OK && !ran)
            rc = ncp_stop_run(a, w->m[NCP_MG_STOP]);
    }
    ncp_offsets_sync_params(a);
    return rc;
}

/* G7 (lathe diameter mode): an X word is a diameter, so the axis moves half
 * of it, whatever uses X (moves, G10, G92, G28, cycles). rs274 halves X as it
 * reads the word when the mode is already on, then, if this block's G7 turns
 * it on, halves it there, or, if its G8 turns it off, doubles it back: done
 * in that order here, so every value (even a subnormal) comes out as rs274's.
 * Before any step of the block uses X, after the checks that only look at
 * whether it is there. */
static void ncp_lathe_x_word(struct ncp_analyzer *a)
{
    struct ncp_words *w = &a->w;
    if (!NCP_HAS(w, 'X'))
        return;
    int before = a->st.m.lathe_diameter, g = w->g[NCP_GG_LATHE];
    double *x = &w->v[NCP_LETTER('X')];
    if (before)
        *x /= 2;
    if (g == NCP_G7 && !before)
        *x /= 2;
    else if (g == NCP_G8 && before)
        *x *= 2;
}

/* A block as rs274 reads and executes it: what the canon did since the last
 * one read back, the words, their checks, then the steps in rs274's order. */
int ncp_an_execute(struct ncp_analyzer *a, const struct ncp_block *b)
{
    a->blk = b;
    int rc = ncp_offsets_resync(a);
    if (rc == NCP_OK)
        rc = ncp_words_collect(a, b);
    if (rc == NCP_OK)
        rc = ncp_words_assign(a, b);
    if (rc == NCP_OK)
        rc = ncp_modal_check(a);
    if (rc == NCP_OK) {
        ncp_lathe_x_word(a);
        rc = ncp_an_steps(a);
    }
    return rc;
}
