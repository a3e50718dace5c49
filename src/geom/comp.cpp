// Cutter compensation offsets. The arithmetic mirrors rs274 operation by
// operation, including where it mixes long double quarter turns into double
// angles: printed coordinates must match its output to the last digit, so
// "simplifying" any expression here changes results.
#include "ncpar/geom.h"

#include <Eigen/Core>
#include <cmath>

namespace {

using Vec2 = Eigen::Vector2d;

constexpr long double kPi = 3.141592653589793238462643383279502884L;
constexpr long double kHalfPi = kPi / 2.0L;
constexpr double kSmall = 0.05;      // rs274 TOLERANCE_CONCAVE_CORNER, radians
constexpr double kEqual = 1e-6;      // rs274 TOLERANCE_EQUAL

Vec2 vec(const double p[2]) { return Vec2(p[0], p[1]); }

void put(double out[2], const Vec2 &v)
{
    out[0] = v.x();
    out[1] = v.y();
}

// Point at distance len from p in direction ang.
Vec2 polar(const Vec2 &p, double len, double ang)
{
    return Vec2(p.x() + len * std::cos(ang), p.y() + len * std::sin(ang));
}

bool tool_inside_arc(int side, int turn)
{
    return (side == NCP_COMP_LEFT && turn > 0) || (side == NCP_COMP_RIGHT && turn < 0);
}

double angle_of(const Vec2 &from, const Vec2 &to)
{
    return std::atan2(to.y() - from.y(), to.x() - from.x());
}

// Concave arc -> line: where the compensated previous arc meets the offset line.
int arc_line_meet(int side, double r, const Vec2 &op, const Vec2 &p,
                  const ncp_comp_prev &prev, Vec2 *mid)
{
    Vec2 pc = vec(prev.centre);
    double oldrad = std::hypot(prev.centre[1] - prev.end[1], prev.centre[0] - prev.end[0]);
    double base_dir = angle_of(op, p);
    double theta = prev.turn > 0 ? (double)(base_dir + kHalfPi) : (double)(base_dir - kHalfPi);
    double phi = angle_of(op, pc);
    bool inside = tool_inside_arc(side, prev.turn);
    double uncomp = inside ? oldrad + r : oldrad - r;
    double d = uncomp * std::cos(theta - phi);
    double l = (inside ? d - r : d + r) / oldrad;
    if (l > 1.0 || l < -1.0)
        return NCP_COMP_E_ARC_LINE_GOUGE;
    bool plus = inside ? prev.turn <= 0 : prev.turn > 0;
    double a = plus ? (double)(std::acos(l) + theta + kPi) : (double)(-std::acos(l) + theta + kPi);
    *mid = polar(pc, oldrad, a);
    return NCP_COMP_OK;
}

// Concave line -> arc: where the offset previous line meets the offset arc.
int line_arc_meet(int side, double r, double beta, double theta, double arc_radius,
                  const Vec2 &centre, int turn, Vec2 *mid)
{
    double cy = (double)(arc_radius * sinl(beta - kHalfPi));
    double dist, ang;
    if (tool_inside_arc(side, turn)) {
        dist = arc_radius - r;
        double l = (cy + r) / dist;
        if (l > 1.0 || l < -1.0)
            return NCP_COMP_E_LINE_ARC_GOUGE;
        ang = turn > 0 ? theta + std::asin(l) : theta - std::asin(l);
    } else {
        dist = arc_radius + r;
        double l = (cy - r) / dist;
        if (l > 1.0 || l < -1.0)
            return NCP_COMP_E_LINE_ARC_GOUGE;
        ang = turn > 0 ? (double)(theta + kPi - std::asin(l)) : (double)(theta + kPi + std::asin(l));
    }
    *mid = polar(centre, dist, ang);
    return NCP_COMP_OK;
}

// Concave arc -> arc: intersection of the two compensated circles.
int arc_arc_meet(int side, double r, double arc_radius, const Vec2 &centre, int turn,
                 const ncp_comp_prev &prev, Vec2 *mid)
{
    double oldrad = std::hypot(prev.centre[1] - prev.end[1], prev.centre[0] - prev.end[0]);
    double newrad = tool_inside_arc(side, turn) ? arc_radius - r : arc_radius + r;
    double arc_cc = std::hypot(prev.centre[1] - centre.y(), prev.centre[0] - centre.x());
    if (oldrad == 0 || arc_cc == 0)
        return NCP_COMP_E_ARC_ARC_CENTRE;
    double a = (oldrad * oldrad + arc_cc * arc_cc - newrad * newrad) / (2 * oldrad * arc_cc);
    if (a > 1.0 || a < -1.0)
        return NCP_COMP_E_ARC_ARC_GOUGE;
    double pullback = std::acos(a);
    double cc_dir = std::atan2(centre.y() - prev.centre[1], centre.x() - prev.centre[0]);
    bool plus = tool_inside_arc(side, prev.turn) ? turn > 0 : turn <= 0;
    double dir = plus ? cc_dir + pullback : cc_dir - pullback;
    *mid = polar(vec(prev.centre), oldrad, dir);
    return NCP_COMP_OK;
}

} // namespace

extern "C" {

const char *ncp_geom_comp_strerror(int status)
{
    switch (status) {
    case NCP_COMP_OK: return "";
    case NCP_COMP_E_ENTRY_SHORT:
        return "Length of cutter compensation entry move is not greater than the tool radius";
    case NCP_COMP_E_ENTRY_ARC_SHORT:
        return "Radius of cutter compensation entry arc is not greater than the tool radius";
    case NCP_COMP_E_TOOL_TOO_BIG: return "Tool radius not less than arc radius with comp";
    case NCP_COMP_E_ZERO_CORNER:
        return "Zero degree inside corner is invalid for cutter compensation";
    case NCP_COMP_E_ARC_LINE_GOUGE:
        return "Arc to straight motion makes a corner the compensated tool can't fit in "
               "without gouging";
    case NCP_COMP_E_LINE_ARC_GOUGE:
        return "Arc move in concave corner cannot be reached by the tool without gouging";
    case NCP_COMP_E_ARC_ARC_CENTRE:
        return "Arc to arc motion is invalid because the arcs have the same center";
    case NCP_COMP_E_ARC_ARC_GOUGE:
        return "Arc to arc motion makes a corner the compensated tool can't fit in "
               "without gouging";
    case NCP_COMP_E_FEED_GOUGE:
        return "Straight feed in concave corner cannot be reached by the tool without gouging";
    case NCP_COMP_E_TRAVERSE_GOUGE:
        return "Straight traverse in concave corner cannot be reached by the tool without "
               "gouging";
    case NCP_COMP_E_ARC_MISMATCH:
        return "BUG: cutter compensation has generated an invalid arc with mismatched radii";
    default: return "Bug in tool radius comp";
    }
}

double ncp_geom_comp_find_turn(const double p1[2], const double c[2], int turn, const double p2[2])
{
    if (turn == 0)
        return 0.0;
    double alpha = std::atan2(p1[1] - c[1], p1[0] - c[0]);
    double beta = std::atan2(p2[1] - c[1], p2[0] - c[0]);
    if (turn > 0) {
        if (beta <= alpha)
            beta = (double)(beta + 2 * kPi);
        return (double)((beta - alpha) + (turn - 1) * (2 * kPi));
    }
    if (alpha <= beta)
        alpha = (double)(alpha + 2 * kPi);
    return (double)((beta - alpha) + (turn + 1) * (2 * kPi));
}

int ncp_geom_comp_line_entry(int side, double r, const double cur[2], const double p[2],
                        double end[2], double dir[2])
{
    Vec2 c = vec(cur), pp = vec(p);
    if (std::hypot(pp.x() - c.x(), pp.y() - c.y()) <= r)
        return NCP_COMP_E_ENTRY_SHORT;
    double alpha = (double)(angle_of(c, pp) + (side == NCP_COMP_LEFT ? kPi / 2. : -kPi / 2.));
    put(end, polar(pp, r, alpha));
    dir[0] = std::cos(alpha);
    dir[1] = std::sin(alpha);
    return NCP_COMP_OK;
}

int ncp_geom_comp_arc_entry(int side, double r, const double cur[2], const double end[2],
                       const double centre[2], int turn, double spiral_abs_tol,
                       double new_end[2], double new_centre[2])
{
    Vec2 c = vec(cur), ctr = vec(centre), e = vec(end);
    double gamma = tool_inside_arc(side, turn) ? angle_of(e, ctr) : angle_of(ctr, e);
    e = polar(e, r, gamma);
    // The compensated arc runs from the uncompensated start to the offset end:
    // its centre slides along the end radius until both are equidistant.
    double b_len = std::hypot(c.y() - e.y(), c.x() - e.x()) / 2.0;
    double ab_ang = angle_of(e, ctr);
    double a_ang = angle_of(e, c) - ab_ang;
    if (std::fabs(std::cos(a_ang)) < kEqual)
        return NCP_COMP_E_TOOL_TOO_BIG;
    Vec2 nc = polar(e, b_len / std::cos(a_ang), ab_ang);
    if (std::fabs(std::hypot(nc.x() - e.x(), nc.y() - e.y()) -
                  std::hypot(nc.x() - c.x(), nc.y() - c.y())) > spiral_abs_tol)
        return NCP_COMP_E_BUG;
    put(new_end, e);
    put(new_centre, nc);
    return NCP_COMP_OK;
}

int ncp_geom_comp_line_next(int side, double r, const double cur[2], const double op[2],
                       const double p[2], const struct ncp_comp_prev *front,
                       struct ncp_comp_corner_out *out)
{
    Vec2 c = vec(cur), o = vec(op), pp = vec(p);
    double theta = angle_of(o, c);
    double alpha = angle_of(o, pp);
    double beta, gamma;
    if (side == NCP_COMP_LEFT) {
        if (theta < alpha)
            theta = (double)(theta + 2 * kPi);
        beta = (double)((theta - alpha) - kHalfPi);
        gamma = (double)kHalfPi;
    } else {
        if (alpha < theta)
            alpha = (double)(alpha + 2 * kPi);
        beta = (double)((alpha - theta) - kHalfPi);
        gamma = (double)-kHalfPi;
    }
    put(out->end, polar(pp, r, alpha + gamma));
    Vec2 mid = polar(o, r, alpha + gamma);
    bool front_arc = front->valid && front->is_arc;
    bool concave = beta < -kSmall || beta > kPi + kSmall;
    // tangent arc then line doubling back: rs274 keeps the tool on the
    // outside ("h" shape) by treating it as an inside corner
    if (!concave && beta > kPi - kSmall && front_arc &&
        ((side == NCP_COMP_RIGHT && front->turn > 0) || (side == NCP_COMP_LEFT && front->turn < 0)))
        concave = true;
    if (!concave) {
        out->corner = beta > kSmall ? NCP_CORNER_CONVEX : NCP_CORNER_STRAIGHT;
        put(out->mid, mid);
        return NCP_COMP_OK;
    }
    out->corner = NCP_CORNER_CONCAVE;
    if (front_arc) {
        int st = arc_line_meet(side, r, o, pp, *front, &mid);
        put(out->mid, mid);
        return st;
    }
    double halfcorner = (double)((beta + kPi) / 2.0);
    if (halfcorner == 0.0)
        return NCP_COMP_E_ZERO_CORNER;
    double retreat = r / std::tan(halfcorner);
    put(out->mid, polar(c, retreat, theta + gamma));
    return NCP_COMP_OK;
}

int ncp_geom_comp_arc_next(int side, double r, const double cur[2], const double op[2],
                      const double end[2], const double centre[2], int ccw, int turn,
                      const struct ncp_comp_prev *front, struct ncp_comp_corner_out *out)
{
    Vec2 c = vec(cur), o = vec(op), e = vec(end), ctr = vec(centre);
    double arc_radius = std::hypot(ctr.x() - e.x(), ctr.y() - e.y());
    double theta = angle_of(o, c);
    theta = side == NCP_COMP_LEFT ? (double)(theta - kHalfPi) : (double)(theta + kHalfPi);
    double delta = angle_of(o, ctr);
    double alpha = ccw ? (double)(delta - kHalfPi) : (double)(delta + kHalfPi);
    double beta = side == NCP_COMP_LEFT ? theta - alpha : alpha - theta;
    if (beta > 1.5 * kPi)
        beta = (double)(beta - 2 * kPi);
    else if (beta < -kHalfPi)
        beta = (double)(beta + 2 * kPi);

    double gamma;
    if ((side == NCP_COMP_LEFT && ccw) || (side == NCP_COMP_RIGHT && !ccw)) {
        gamma = angle_of(e, ctr);
        if (arc_radius <= r)
            return NCP_COMP_E_TOOL_TOO_BIG;
    } else {
        gamma = angle_of(ctr, e);
        delta = (double)(delta + kPi);
    }
    put(out->end, polar(e, r, gamma));

    bool concave = beta < -kSmall || beta > kPi + kSmall ||
                   (fabsl(beta - kPi) < kSmall && !tool_inside_arc(side, turn));
    Vec2 mid = c;
    int st = NCP_COMP_OK;
    if (concave) {
        out->corner = NCP_CORNER_CONCAVE;
        if (front->valid && front->is_arc)
            st = arc_arc_meet(side, r, arc_radius, ctr, turn, *front, &mid);
        else
            st = line_arc_meet(side, r, beta, theta, arc_radius, ctr, turn, &mid);
    } else if (beta > kSmall) {
        out->corner = NCP_CORNER_CONVEX2;
        mid = polar(o, r, delta);
    } else {
        out->corner = NCP_CORNER_STRAIGHT;
    }
    put(out->mid, mid);
    return st;
}

} // extern "C"
