// Arc geometry in rs274's order of operations: hypot() for lengths (not
// sqrt of a sum of squares), the perpendicular direction from atan2 with a
// long double quarter turn, and the centre offset via asin/cos. Any other
// algebraically equal form drifts in the last bits and can flip a printed
// fourth decimal.
#include "ncpar/geom.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace {

using Vec2 = Eigen::Vector2d;

// Half-length / radius ratio above which the chord counts as a diameter:
// rs274 snaps near-semicircles so asin() never sees a ratio above 1.
constexpr double kSemicircleSnap = 1e-12;
constexpr long double kQuarterTurn = 1.570796326794896619231321691639751442L;

double len(const Vec2 &v) { return std::hypot(v.x(), v.y()); }

int solve_centre_form(const ncp_arc_in &in, ncp_arc_out &out)
{
    const Vec2 start(in.start[0], in.start[1]);
    const Vec2 end(in.end[0], in.end[1]);
    const Vec2 centre(in.centre[0], in.centre[1]);
    out.centre[0] = centre.x();
    out.centre[1] = centre.y();
    out.r1 = len(centre - start);
    out.r2 = len(centre - end);
    out.abs_err = std::fabs(out.r1 - out.r2);
    out.rel_err = out.abs_err / std::max(out.r1, out.r2);
    if (out.r1 < in.radius_tol || out.r2 < in.radius_tol)
        return NCP_ARC_ZERO_RADIUS;
    if (out.abs_err > in.spiral_abs_tol * 100.0 ||
        (out.rel_err > in.spiral_rel_tol && out.abs_err > in.spiral_abs_tol))
        return NCP_ARC_RADIUS_DIFFERS;
    return NCP_ARC_OK;
}

int solve_radius_form(const ncp_arc_in &in, ncp_arc_out &out)
{
    const Vec2 start(in.start[0], in.start[1]);
    const Vec2 end(in.end[0], in.end[1]);
    if (start == end)
        return NCP_ARC_SAME_POINT;
    const double r = std::fabs(in.radius);
    const Vec2 mid = (end + start) / 2.0;
    double half = len(mid - end);
    if (half - r > in.radius_tol)
        return NCP_ARC_R_TOO_SMALL;
    if (half / r > 1 - kSemicircleSnap)
        half = r;
    // The centre lies right of the chord for a short cw arc or a long ccw arc.
    const bool right = in.ccw ? in.radius < 0 : in.radius > 0;
    const Vec2 chord = end - start;
    const long double dir = std::atan2(chord.y(), chord.x());
    const double theta = static_cast<double>(right ? dir - kQuarterTurn : dir + kQuarterTurn);
    const double offset = r * std::cos(std::asin(half / r));
    const Vec2 centre = mid + Vec2(offset * std::cos(theta), offset * std::sin(theta));
    out.centre[0] = centre.x();
    out.centre[1] = centre.y();
    return NCP_ARC_OK;
}

constexpr long double kFullTurn = 2 * 3.141592653589793238462643383279502884L;

// Swept angle, ccw positive. The wrap-around additions happen in long double
// and are rounded back to double at each step, as rs274 does.
double swept_angle(const Vec2 &start, const Vec2 &centre, const Vec2 &end, int rotation)
{
    if (rotation == 0)
        return 0.0;
    const Vec2 from = start - centre;
    const Vec2 to = end - centre;
    double alpha = std::atan2(from.y(), from.x());
    double beta = std::atan2(to.y(), to.x());
    if (rotation > 0) {
        if (beta <= alpha)
            beta = static_cast<double>(beta + kFullTurn);
        return static_cast<double>((beta - alpha) + (rotation - 1) * kFullTurn);
    }
    if (alpha <= beta)
        alpha = static_cast<double>(alpha + kFullTurn);
    return static_cast<double>((beta - alpha) + (rotation + 1) * kFullTurn);
}

} // namespace

extern "C" double ncp_geom_arc_length(const ncp_arc_in *in, const ncp_arc_out *out,
                                 double axis_start, double axis_end)
{
    const Vec2 start(in->start[0], in->start[1]);
    const Vec2 end(in->end[0], in->end[1]);
    const Vec2 centre(out->centre[0], out->centre[1]);
    const double radius = len(centre - start);
    const double theta = swept_angle(start, centre, end, out->rotation);
    if (axis_end == axis_start)
        return radius * std::fabs(theta);
    return std::hypot(radius * theta, axis_end - axis_start);
}

extern "C" int ncp_geom_arc_solve(const ncp_arc_in *in, ncp_arc_out *out)
{
    *out = ncp_arc_out{};
    out->rotation = in->ccw ? in->turns : -in->turns;
    return in->radius_form ? solve_radius_form(*in, *out) : solve_centre_form(*in, *out);
}
