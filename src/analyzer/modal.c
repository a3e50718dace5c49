/* Whole-block consistency checks, done once per block on the word bitmask:
 * which motion the block performs, axis words without a user, words without a
 * G/M code that uses them (rs274's enhance_block and check_* rules). */
#include "floor.h"
#include "stages.h"

#include <math.h>

#define BIT(c) (1u << NCP_LETTER(c))

/* G70, G71, G71.1, G71.2, G72, G72.1, G72.2 */
static int ncp_is_g7x(int m)
{
    return m == NCP_G70 || (m >= NCP_G71 && m <= NCP_G71_2) || (m >= NCP_G72 && m <= NCP_G72_2);
}

static int ncp_first_axis_col(const struct ncp_words *w)
{
    static const char ax[] = "XYZABCUVW";
    int best = 0;
    for (const char *p = ax; *p; p++)
        if (NCP_HAS(w, *p) && (best == 0 || w->col[NCP_LETTER(*p)] < best))
            best = w->col[NCP_LETTER(*p)];
    return best;
}

static int ncp_motion_to_be(struct ncp_analyzer *a)
{
    struct ncp_words *w = &a->w;
    int axis = (w->has & (NCP_AXIS_LETTERS | NCP_POLAR_BITS)) != 0;
    int ijk = (w->has & (BIT('I') | BIT('J') | BIT('K'))) != 0;
    int m0 = w->g[NCP_GG_NONMODAL], m1 = w->g[NCP_GG_MOTION];
    int covets = m0 == NCP_G10 || m0 == NCP_G28 || m0 == NCP_G30 || m0 == NCP_G52 || m0 == NCP_G92;
    int tlo = w->g[NCP_GG_TLO];
    w->motion_to_be = -1;
    if (m1 != -1) {
        uint16_t col = w->gcol[NCP_GG_MOTION];
        if (m1 == NCP_G80) {
            if (axis && !covets)
                return ncp_an_error(a, col, "Cannot use axis values with g80");
            if (!axis && (m0 == NCP_G52 || m0 == NCP_G92))
                return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                                    "All axes missing with g52 or g92");
        } else {
            if (covets)
                return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                                    "Cannot use two g codes that both use axis values");
            /* a remapped code of its own takes no word but its argspec's,
             * which its remap checks (words.c marked the block remapped) */
            if (!axis && m1 != NCP_G0 && m1 != NCP_G1 && m1 != NCP_G2 && m1 != NCP_G3 &&
                m1 != NCP_G5_2 && !ncp_is_g7x(m1) && !ncp_remapped_g(a, m1))
                return ncp_an_error(a, col, "All axes missing with motion code");
        }
        w->motion_to_be = m1;
    } else if (covets) {
        if (!axis && (m0 == NCP_G52 || m0 == NCP_G92))
            return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                                "All axes missing with g52 or g92");
    } else if (axis) {
        int mm = a->st.m.motion;
        if ((mm == -1 || mm == NCP_G80) && tlo != NCP_G43_1 && tlo != NCP_G43_2)
            return ncp_an_error(a, ncp_first_axis_col(w),
                                "Cannot use axis values without a g code that uses them");
        if (tlo != NCP_G43_1)
            w->motion_to_be = mm;
    } else if (ijk && (a->st.m.motion == NCP_G2 || a->st.m.motion == NCP_G3)) {
        w->motion_to_be = a->st.m.motion;
    }
    return NCP_OK;
}

static int ncp_check_g(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int m0 = w->g[NCP_GG_NONMODAL], m1 = w->g[NCP_GG_MOTION];
    uint16_t col = w->gcol[NCP_GG_NONMODAL];
    if (m0 == -1)
        return NCP_OK;
    if (m0 == NCP_G4) {
        if (!NCP_HAS(w, 'P') || w->v[NCP_LETTER('P')] == -1.0) /* rs274: P-1 is no P */
            return ncp_an_error(a, col, "Dwell time missing with g4");
        if (m1 == NCP_G2 || m1 == NCP_G3)
            return ncp_an_error(a, col, "G4 not allowed with G2 or G3 because they both use P");
    } else if (m0 == NCP_G10) {
        double p = NCP_HAS(w, 'P') ? w->v[NCP_LETTER('P')] : -1.0;
        int l = NCP_HAS(w, 'L') ? ncp_trunc_int_round(w->v[NCP_LETTER('L')]) : -1;
        int pi = p >= 0 ? ncp_trunc_int(p + 0.5) : ncp_trunc_int(p - 0.5);
        if (l != 0 && l != 1 && l != 2 && l != 10 && l != 11 && l != 20)
            return ncp_an_error(a, col, "Line with G10 does not have L0, L1, L10, L11, L2, or L20");
        if (p + 0.0001 - pi > 0.0002)
            return ncp_an_error(a, col, "P value not an integer with G10");
        if ((l == 2 || l == 20) && (pi < 0 || pi > 9))
            return ncp_an_error(a, col, "P value out of range (0-9) with G10 L%d", l);
        if ((l == 1 || l == 10 || l == 11) && pi < 1)
            return ncp_an_error(a, col, "P value out of range with G10 L%d", l);
    } else if (m0 == NCP_G5_3) {
        if (m1 != NCP_G5_2 && m1 != -1)
            return ncp_an_error(a, col, "Between G5.2 and G5.3 codes, only additional G5.2 codes are allowed.");
    } else if (m0 == NCP_G53 && m1 != NCP_G5_2) { /* rs274 checks no G53 beside G5.2 */
        int mt = w->motion_to_be;
        if (mt != NCP_G0 && mt != NCP_G1)
            return ncp_an_error(a, col, "Must use g0 or g1 with g53");
        if (w->g[NCP_GG_DIST] == NCP_G91 || (w->g[NCP_GG_DIST] != NCP_G90 && a->st.m.incremental))
            return ncp_an_error(a, col, "Cannot use g53 incremental");
    }
    return NCP_OK;
}

/* Words that need a code to use them. */
static int ncp_check_other(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int mt = w->motion_to_be;
    if (w->remapped) /* rs274: the remap's argspec takes care of its words */
        return NCP_OK;
#define BIT(c) (1u << NCP_LETTER(c))
    /* every check below needs one of these words, G96 or G33/G33.1/G76: a
     * plain move (X Y Z F) has none of them, one test instead of the list */
    const uint32_t checked = BIT('A') | BIT('B') | BIT('C') | BIT('D') | BIT('E') | BIT('H') |
                             BIT('I') | BIT('J') | BIT('K') | BIT('L') | BIT('P') | BIT('Q') |
                             BIT('R');
#undef BIT
    if (!(w->has & checked) && w->g[NCP_GG_SPINDLE] != NCP_G96 && mt != NCP_G33 &&
        mt != NCP_G33_1 && mt != NCP_G76)
        return NCP_OK;
    int m0 = w->g[NCP_GG_NONMODAL];
    int comp = w->g[NCP_GG_COMP];
    int tlo = w->g[NCP_GG_TLO];
    int ctl = w->g[NCP_GG_CONTROL];
    int g10 = m0 == NCP_G10;
    int comp_on = comp == NCP_G41 || comp == NCP_G42 || comp == NCP_G41_1 || comp == NCP_G42_1;
    int g70 = mt == NCP_G70, rough = ncp_is_g7x(mt) && !g70; /* rough: G71*, G72* */
#define COL(c) w->col[NCP_LETTER(c)]
    if (NCP_HAS(w, 'A') && ncp_is_canned_cycle(mt))
        return ncp_an_error(a, COL('A'), "Cannot put an a in canned cycle");
    if (NCP_HAS(w, 'B') && ncp_is_canned_cycle(mt))
        return ncp_an_error(a, COL('B'), "Cannot put a b in canned cycle");
    if (NCP_HAS(w, 'C') && ncp_is_canned_cycle(mt))
        return ncp_an_error(a, COL('C'), "Cannot put a c in canned cycle");
    if (NCP_HAS(w, 'D') && !comp_on && !ncp_is_g7x(mt) && w->g[NCP_GG_SPINDLE] != NCP_G96)
        return ncp_an_error(a, COL('D'), "D word with no G41, G41.1, G42, G42.1, G71, G71.1, G71.2 or G96 to use it");
    if (NCP_HAS(w, 'E') && mt != NCP_G76 && mt != NCP_G33 && mt != NCP_G33_1 && !g70 &&
        w->m[NCP_MG_IO] != NCP_M66 && w->m[NCP_MG_IO] != NCP_M67 && w->m[NCP_MG_IO] != NCP_M68)
        return ncp_an_error(a, COL('E'), "E word with no G70, G76, M66, M67 or M68 to use it");
    if (NCP_HAS(w, 'H') && tlo != NCP_G43 && mt != NCP_G76 && tlo != NCP_G43_2)
        return ncp_an_error(a, COL('H'), "H word with no G43 or G76 to use it");
    if (NCP_HAS(w, 'I') && mt != NCP_G2 && mt != NCP_G3 && mt != NCP_G5 && mt != NCP_G5_1 &&
        mt != NCP_G76 && mt != NCP_G87 && mt != NCP_G33_1 && !rough && !g10)
        return ncp_an_error(a, COL('I'), "I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use it");
    if (NCP_HAS(w, 'J') && mt != NCP_G2 && mt != NCP_G3 && mt != NCP_G5 && mt != NCP_G5_1 &&
        mt != NCP_G76 && mt != NCP_G87 && !g10)
        return ncp_an_error(a, COL('J'), "J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it");
    if (NCP_HAS(w, 'K') && mt != NCP_G2 && mt != NCP_G3 && mt != NCP_G33 && mt != NCP_G33_1 &&
        mt != NCP_G76 && mt != NCP_G87)
        return ncp_an_error(a, COL('K'), "K word with no G2, G3, G33, G33.1, G76, or G87 to use it");
    if (NCP_HAS(w, 'L') && (mt < NCP_G81 || mt > NCP_G89) && mt != NCP_G76 && mt != NCP_G5_2 &&
        mt != NCP_G73 && !g10 && !comp_on && w->m[NCP_MG_IO] != NCP_M66 && !w->m98)
        return ncp_an_error(a, COL('L'), "L word with no G10, cutter compensation, canned cycle, digital/analog input, M98 or NURBS code");
    if (NCP_HAS(w, 'P')) {
        int mo = w->m[NCP_MG_OVERRIDE], mi = w->m[NCP_MG_IO];
        if (!g10 && m0 != NCP_G4 && ctl != NCP_G64 && mt != NCP_G76 && mt != NCP_G82 &&
            mt != NCP_G86 && mt != NCP_G88 && mt != NCP_G89 && mt != NCP_G5 && mt != NCP_G5_2 &&
            mt != NCP_G2 && mt != NCP_G3 && mt != NCP_G84 && mt != NCP_G74 && !g70 &&
            (mo < NCP_M50 || mo > NCP_M53) && (mi < NCP_M62 || mi > NCP_M66) &&
            w->m[NCP_MG_SPINDLE] != NCP_M19 && !w->m98 && w->m[NCP_MG_USER] == -1)
            return ncp_an_error(a, COL('P'), "P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or M50 M51 M52 M53 M62 M63 M64 M65 M66 M98 or user M code to use it");
        double p = w->v[NCP_LETTER('P')];
        int pv = ncp_trunc_int_round(p);
        int arc = mt == NCP_G2 || mt == NCP_G3;
        if ((arc || w->m[NCP_MG_SPINDLE] == NCP_M19) && fabs(pv - p) > 0.001)
            return ncp_an_error(a, COL('P'), "P value not an integer with M19 G2 or G3");
        if (w->m[NCP_MG_SPINDLE] == NCP_M19 && (pv > 2 || pv < 0))
            return ncp_an_error(a, COL('P'), "P value must be 0,1,or 2 with M19");
        if (arc && pv < 1)
            return ncp_an_error(a, COL('P'), "P value should be 1 or greater with G2 or G3");
    }
    if (NCP_HAS(w, 'Q') && mt != NCP_G83 && mt != NCP_G73 && mt != NCP_G5 && mt != NCP_G76 &&
        !ncp_is_g7x(mt) && w->m[NCP_MG_IO] != NCP_M66 && w->m[NCP_MG_IO] != NCP_M67 &&
        w->m[NCP_MG_IO] != NCP_M68 && !g10 && w->m[NCP_MG_TOOL] != NCP_M61 && ctl != NCP_G64 &&
        w->m[NCP_MG_SPINDLE] != NCP_M19 && w->m[NCP_MG_USER] == -1)
        return ncp_an_error(a, COL('Q'), "Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or user M code that uses it");
    if (NCP_HAS(w, 'R') && mt != NCP_G2 && mt != NCP_G3 && mt != NCP_G76 &&
        !ncp_is_canned_cycle(mt) && !rough && comp != NCP_G41_1 && comp != NCP_G42_1 && !g10 &&
        w->m[NCP_MG_SPINDLE] != NCP_M19)
        return ncp_an_error(a, COL('R'), "R word with no g code that uses it");
    if (!NCP_HAS(w, 'S') && w->g[NCP_GG_SPINDLE] == NCP_G96)
        return ncp_an_error(a, w->gcol[NCP_GG_SPINDLE], "S word missing with g96");
    if (mt == NCP_G33 || mt == NCP_G33_1) {
        if (!NCP_HAS(w, 'K'))
            return ncp_an_error(a, NCP_MOTION_COL(w),
                                "K word missing with g33/g33.1");
        if (NCP_HAS(w, 'F'))
            return ncp_an_error(a, COL('F'), "F word used with a g33/g33.1");
    }
    if (mt == NCP_G76) {
        uint16_t col = NCP_MOTION_COL(w);
        if (!NCP_HAS(w, 'P') || w->v[NCP_LETTER('P')] == -1.0) /* rs274: P-1 is no P */
            return ncp_an_error(a, col, "P word missing with G76");
        if (!NCP_HAS(w, 'I') || !NCP_HAS(w, 'J') || !NCP_HAS(w, 'K'))
            return ncp_an_error(a, col, "I J or K words missing with G76");
    }
#undef COL
    return NCP_OK;
}

int ncp_modal_check(struct ncp_analyzer *a)
{
    int rc = ncp_motion_to_be(a);
    if (rc == NCP_OK)
        rc = ncp_check_g(a);
    /* rs274 checks the M count after the G codes: at most MAX_EMS, 4 */
    if (rc == NCP_OK && a->w.n_m > 4)
        rc = ncp_an_error(a, a->w.line_col, "Too many m codes on line");
    if (rc == NCP_OK)
        rc = ncp_check_other(a);
    return rc;
}
