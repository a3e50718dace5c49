/* G70 (finishing), G71/G71.1/G71.2 (roughing along Z) and G72/G72.1/G72.2
 * (roughing along X) as rs274 2.9 runs them. The profile is the subroutine
 * named by Q: rs274 calls it and reads its blocks in a recording mode, where
 * only O-words, parameter assignments and the motion words count (X Z U W,
 * I K R, A fillets, C chamfers, the motion G code); no other word of those
 * blocks is executed, not even a comment. The passes then go out as G0/G1/
 * G2/G3 moves through the ordinary motion code, with the distance modes
 * forced to absolute for the whole cycle, as rs274 does.
 *
 * What rs274 does besides is kept because programs can see it: its current
 * point follows the recorded profile (#<_x>, #5420 read it in the
 * subroutine, and after the cycle the moves start from its end), the motion
 * mode is the last one used, and once the subroutine has been read the
 * block in hand is its return line, so the G7x line's own later steps (an M2
 * on it) are lost and errors of the passes name that return line. */
#include "floor.h"
#include "offsets.h"
#include "stages.h"

#include "ncpar/blocks.h"
#include "g7x_path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BIT(c) (1u << NCP_LETTER(c))
#define WV(w, c) ((w)->v[NCP_LETTER(c)])

/* rs274's current point in the XZ plane: the compensated one while cutter
 * compensation has moved. */
static double complex g7x_current(const struct ncp_analyzer *a)
{
    if (ncp_cutcomp_engaged(&a->comp) && !a->comp.firstmove)
        return CMPLX(a->comp.cur[0], a->comp.cur[1]);
    return CMPLX(a->st.pos[NCP_Z], a->st.pos[NCP_X]);
}

static void g7x_set_current(struct ncp_analyzer *a, double complex p)
{
    a->st.pos[NCP_X] = cimag(p);
    a->st.pos[NCP_Z] = creal(p);
    if (ncp_cutcomp_engaged(&a->comp) && !a->comp.firstmove) {
        a->comp.cur[0] = creal(p);
        a->comp.cur[1] = cimag(p);
    }
}

/* The block rs274 has in hand once the subroutine returned: no words. */
static void g7x_blank_words(struct ncp_words *w, uint16_t col)
{
    w->has = 0;
    w->n_m = 0;
    memset(w->g, 0xff, sizeof w->g);
    memset(w->m, 0xff, sizeof w->m);
    memset(w->gcol, 0, sizeof w->gcol);
    w->line_col = col;
    w->motion_to_be = -1;
}

/* ---------------------------------------------------------------------
 * The passes: moves through the ordinary motion code
 * --------------------------------------------------------------------- */

static void g7x_end_words(struct ncp_words *w, double complex end)
{
    w->has |= BIT('X') | BIT('Z');
    WV(w, 'X') = cimag(end);
    WV(w, 'Z') = creal(end);
}

static int g7x_line(void *ctx, int rapid, double complex end)
{
    struct ncp_analyzer *a = ctx;
    g7x_end_words(&a->w, end);
    return ncp_motion_straight(a, rapid ? NCP_G0 : NCP_G1);
}

/* rs274 skips an arc that ends where it starts (within 0.0001). */
static int g7x_arc(void *ctx, int ccw, double complex centre, double complex end)
{
    struct ncp_analyzer *a = ctx;
    struct ncp_words *w = &a->w;
    g7x_end_words(w, end);
    w->has |= BIT('I') | BIT('K');
    WV(w, 'I') = cimag(centre);
    WV(w, 'K') = creal(centre);
    double complex cur = g7x_current(a);
    if (fabs(creal(cur) - creal(end)) < 0.0001 && fabs(cimag(cur) - cimag(end)) < 0.0001)
        return NCP_OK;
    return ncp_motion_arc(a, ccw ? NCP_G3 : NCP_G2);
}

/* ---------------------------------------------------------------------
 * Recording the profile
 * --------------------------------------------------------------------- */

/* rs274 reads "O<Q as %f> call": Q must be an integer, as any O number. */
static int g7x_call(struct ncp_analyzer *a, const struct ncp_words *w)
{
    uint16_t col = w->col[NCP_LETTER('Q')];
    int n;
    int rc = ncp_integer_word(a, WV(w, 'Q'), col, &n);
    if (rc != NCP_OK)
        return rc;
    char text[32];
    int len = snprintf(text, sizeof text, "o%d call", n);
    return ncp_an_call_text(a, text, (size_t)len, col);
}

struct g7x_rec {
    double complex start;         /* the current point */
    int incremental, arc_incremental; /* the program's modes (forced absolute meanwhile) */
};

static int g7x_arc_centre(struct ncp_analyzer *a, const struct g7x_rec *r, double complex end,
                          double complex *centre)
{
    const struct ncp_words *w = &a->w;
    int has_ik = (w->has & (BIT('I') | BIT('K'))) != 0;
    if (NCP_HAS(w, 'R')) {
        if (has_ik)
            return ncp_an_error(a, NCP_MOTION_COL(w),
                                "G7X error: both R and I or K flag used for arc");
        double rad = WV(w, 'R'), n2 = creal(end - r->start) * creal(end - r->start) +
                                      cimag(end - r->start) * cimag(end - r->start);
        double complex d = I * sqrt((rad * rad - n2 / 4) / n2) * (end - r->start);
        *centre = (r->start + end) / 2.0;
        *centre = a->st.m.motion == 30 ? *centre + d : *centre - d;
        return NCP_OK;
    }
    if (!has_ik)
        return ncp_an_error(a, NCP_MOTION_COL(w),
                            "G7X error: either I or K must be present for arc");
    if (r->arc_incremental)
        *centre += r->start;
    return NCP_OK;
}

/* One block of the profile: where it ends, and the segment it adds. */
static int g7x_record_block(struct ncp_analyzer *a, struct g7x_rec *r,
                            struct ncp_g7x_path *path)
{
    const struct ncp_words *w = &a->w;
    double complex end = r->incremental ? 0 : r->start, centre = 0;
    if (NCP_HAS(w, 'U')) {
        uint16_t col = w->col[NCP_LETTER('U')];
        if (r->incremental)
            return ncp_an_error(a, col, "G7x error: Cannot use U in incremental mode (G91)");
        if (NCP_HAS(w, 'X'))
            return ncp_an_error(a, col, "G7x error: Cannot use U and X in the same block");
        double u = WV(w, 'U');
        if (a->st.m.lathe_diameter)
            u /= 2;
        end = CMPLX(creal(end), cimag(end) + u);
    } else if (NCP_HAS(w, 'X')) {
        end = CMPLX(creal(end), WV(w, 'X'));
    }
    if (NCP_HAS(w, 'W')) {
        uint16_t col = w->col[NCP_LETTER('W')];
        if (r->incremental)
            return ncp_an_error(a, col, "G7x error: Cannot use W in incremental mode (G91)");
        if (NCP_HAS(w, 'Z'))
            return ncp_an_error(a, col, "G7x error: Cannot use W and Z in the same block");
        end = CMPLX(creal(end) + WV(w, 'W'), cimag(end));
    } else if (NCP_HAS(w, 'Z')) {
        end = CMPLX(WV(w, 'Z'), cimag(end));
    }
    if (NCP_HAS(w, 'I'))
        centre = CMPLX(creal(centre), WV(w, 'I'));
    if (NCP_HAS(w, 'K'))
        centre = CMPLX(WV(w, 'K'), cimag(centre));
    if (r->incremental)
        end += r->start;
    if (w->g[NCP_GG_MOTION] != -1)
        a->st.m.motion = w->g[NCP_GG_MOTION];
    if (r->start == end)
        return NCP_OK;
    int motion = a->st.m.motion, rc = NCP_OK;
    int drawn = motion == NCP_G0 || motion == NCP_G1 || motion == NCP_G2 || motion == NCP_G3;
    if (motion == NCP_G0 || motion == NCP_G1) {
        rc = ncp_g7x_add_line(path, r->start, end);
    } else if (motion == NCP_G2 || motion == NCP_G3) {
        rc = g7x_arc_centre(a, r, end, &centre);
        if (rc == NCP_OK)
            rc = ncp_g7x_add_arc(path, motion == NCP_G3, r->start, centre, end);
    }
    if (rc == NCP_G7X_EGEOM)
        return ncp_an_error(a, NCP_MOTION_COL(w), "G7X error: %s", path->err);
    if (rc == NCP_OK && drawn) {
        if (NCP_HAS(w, 'A') && NCP_HAS(w, 'C'))
            return ncp_an_error(a, w->col[NCP_LETTER('C')],
                                "G7X error: Both A and C parameters on a corner");
        if (NCP_HAS(w, 'A'))
            rc = ncp_g7x_add_corner(path, NCP_G7X_FILLET, WV(w, 'A'), end);
        if (NCP_HAS(w, 'C'))
            rc = ncp_g7x_add_corner(path, NCP_G7X_CHAMFER, WV(w, 'C'), end);
        if (rc == NCP_G7X_EGEOM)
            return ncp_an_error(a, w->line_col, "G7X error: %s", path->err);
    }
    if (rc != NCP_OK)
        return rc;
    g7x_set_current(a, end);
    r->start = end;
    return NCP_OK;
}

/* Read the subroutine's blocks as rs274's recording loop does, up to its
 * return; *ret is then the return line (line and column). */
static int g7x_record(struct ncp_analyzer *a, struct g7x_rec *r, struct ncp_g7x_path *path,
                      struct ncp_block *relex, uint32_t *ret_line, uint16_t *ret_col)
{
    for (;;) {
        const struct ncp_block *b;
        int rc = ncp_an_sub_next(a, &b);
        if (rc == NCP_FLOW_RETURNED) {
            *ret_line = b->line;
            *ret_col = b->oword.col;
            return NCP_OK;
        }
        if (rc != NCP_OK)
            return rc;
        const struct ncp_source *src = ncp_flow_source(a->flow);
        /* it may be a U or W word, which rs274 takes here */
        if (b->err.code != NCP_OK && relex && ncp_blocks_relex_profile(src, b, relex) == 0 &&
            (relex->err.code != NCP_OK || relex->oword.kind == NCP_O_NONE))
            b = relex;
        a->blk = b;
        a->line = b->line;
        a->file_tag = ncp_flow_file_tag(a->flow);
        if (b->err.code != NCP_OK) {
            a->err = b->err;
            return b->err.code;
        }
        /* what rs274's read does: #5420.. from the current point, the words,
         * the block checks (parameters are set after them, which only
         * matters when they fail, and then nothing goes on) */
        ncp_offsets_sync_params(a);
        rc = ncp_words_collect(a, b);
        if (rc == NCP_OK)
            rc = ncp_words_assign(a, b);
        if (rc == NCP_OK)
            rc = ncp_modal_check(a);
        if (rc != NCP_OK)
            return rc;
        if (a->st.m.lathe_diameter && NCP_HAS(&a->w, 'X'))
            WV(&a->w, 'X') /= 2;
        rc = g7x_record_block(a, r, path);
        if (rc != NCP_OK)
            return rc;
    }
}

/* ---------------------------------------------------------------------
 * The cycle
 * --------------------------------------------------------------------- */

static int g7x_checks(struct ncp_analyzer *a, int motion)
{
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    if (!NCP_HAS(w, 'Q'))
        return ncp_an_error(a, col, "G7x.x  requires a Q word");
    if (a->st.m.comp_side != 0 && motion != NCP_G70)
        return ncp_an_error(a, col, "G%d.%d cannot be used with cutter compensation enabled",
                            motion / 10, motion % 10);
    if (a->st.m.plane != 2)
        return ncp_an_error(a, col, "G%d.%d can only be used in XZ plane (G18)", motion / 10,
                            motion % 10);
    return NCP_OK;
}

static double g7x_word(const struct ncp_words *w, char c, double dflt)
{
    return NCP_HAS(w, c) ? WV(w, c) : dflt;
}

static int g7x_passes(struct ncp_analyzer *a, int motion, const struct ncp_words *w,
                      struct ncp_g7x_path *path, double complex start)
{
    double d = g7x_word(w, 'D', 0), i = g7x_word(w, 'I', 1);
    if (i <= 0)
        return ncp_an_error(a, a->w.line_col, "G7X error: I must be greater than zero.");
    struct ncp_g7x_out out = {a, g7x_line, g7x_arc};
    int rc;
    if (motion == NCP_G70) {
        rc = ncp_g7x_finish(path, &out, start, d, g7x_word(w, 'E', 0), g7x_word(w, 'P', 1));
    } else {
        double complex uw = CMPLX(g7x_word(w, 'W', 0), g7x_word(w, 'U', 0));
        int facing = motion == NCP_G72 || motion == NCP_G72_1 || motion == NCP_G72_2;
        rc = ncp_g7x_rough(path, &out, motion % 10, facing, start, uw, d, i,
                           g7x_word(w, 'R', 0.5));
    }
    if (rc == NCP_G7X_EGEOM)
        return ncp_an_error(a, a->w.line_col, "G7X error: %s", path->err);
    return rc;
}

int ncp_g7x_run(struct ncp_analyzer *a, int motion)
{
    int rc = g7x_checks(a, motion);
    if (rc != NCP_OK)
        return rc;
    struct ncp_modal *m = &a->st.m;
    struct g7x_rec r = {.incremental = m->incremental, .arc_incremental = m->arc_incremental};
    /* the G7x block's words: the recording reads the subroutine's over them */
    struct ncp_words blk = a->w;
    double complex start = g7x_current(a);
    double x = cimag(start), z = creal(start);
    if (NCP_HAS(&blk, 'X'))
        x = r.incremental ? x + WV(&blk, 'X') : WV(&blk, 'X');
    if (NCP_HAS(&blk, 'Z'))
        z = r.incremental ? z + WV(&blk, 'Z') : WV(&blk, 'Z');
    r.start = CMPLX(z, x);
    m->incremental = m->arc_incremental = 0;
    /* the rapid to the block's point, its words taken as absolute */
    rc = ncp_motion_straight(a, 0);
    struct ncp_g7x_path path;
    ncp_g7x_path_init(&path);
    uint32_t ret_line = a->line;
    unsigned ret_file = a->file_tag; /* the G7x block's, back after the profile */
    uint16_t ret_col = 1;
    if (rc == NCP_OK)
        rc = g7x_call(a, &blk);
    struct ncp_block *relex = malloc(sizeof *relex); /* NULL: U/W stay refused */
    if (rc == NCP_OK)
        rc = g7x_record(a, &r, &path, relex, &ret_line, &ret_col);
    free(relex);
    a->blk = NULL; /* the G7x block may be gone: the subroutine's were read over it */
    if (rc == NCP_OK) {
        a->line = ret_line;
        a->file_tag = ret_file;
        ncp_an_reline(a);
        g7x_blank_words(&a->w, ret_col);
        if (path.n > 1)
            rc = g7x_passes(a, motion, &blk, &path, CMPLX(z, x));
    }
    ncp_g7x_path_free(&path);
    m->incremental = r.incremental;
    m->arc_incremental = r.arc_incremental;
    return rc;
}
