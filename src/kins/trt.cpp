// Table-rotary-tilting kinematics as rigid motions. With the C table turning
// about rot_point r and the tilting table's pivot at r + d (d: the offsets,
// with the tool length added to its Z, as LinuxCNC's trtfuncs do), a joint
// position j (spindle nose) seen from the work is
//     world = r + Rz(-c) (R_tilt(-t) (j - r - d) + d)
// and so j = r + d + R_tilt(t) (Rz(c) (world - r) - d). R_tilt is a turn about
// X for A (xyzac) and about Y for B (xyzbc); the signs are those of
// LinuxCNC's modules, so a part program made for them cuts the same part.
#include "ncpar/kins.h"

#include <Eigen/Geometry>
#include <cctype>
#include <cmath>

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

constexpr double kDegToRad = M_PI / 180.0;

Mat3 turn(double deg, const Vec3 &axis)
{
    return Eigen::AngleAxisd(deg * kDegToRad, axis).toRotationMatrix();
}

// The tilt's rotation for a tilt angle t (degrees), and the offset vector d.
struct Trt {
    Vec3 r, d;
    Vec3 tilt_axis;
    int tilt;   // axis index of the tilt angle
};

Trt setup(const ncp_kins &k, double tool_z)
{
    Trt t;
    t.r = Vec3(k.rot_point[0], k.rot_point[1], k.rot_point[2]);
    // xyzac: the A pivot is offset in Y and Z; xyzbc: the B pivot in X and Z
    if (k.type == NCP_KINS_XYZAC_TRT) {
        t.d = Vec3(0.0, k.offset[1], k.offset[2] + tool_z);
        t.tilt_axis = Vec3::UnitX();
        t.tilt = 3;
    } else {
        t.d = Vec3(k.offset[0], 0.0, k.offset[2] + tool_z);
        t.tilt_axis = Vec3::UnitY();
        t.tilt = 4;
    }
    return t;
}

void copy_all(const double *from, double *to)
{
    for (int i = 0; i < NCP_KINS_JOINTS; i++)
        to[i] = from[i];
}

bool same_name(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (std::tolower(static_cast<unsigned char>(*a)) != *b)
            return false;
    return *a == *b;
}

} // namespace

extern "C" int ncp_kins_parse(const char *name)
{
    if (same_name(name, "trivkins"))
        return NCP_KINS_TRIVIAL;
    if (same_name(name, "xyzac-trt"))
        return NCP_KINS_XYZAC_TRT;
    if (same_name(name, "xyzbc-trt"))
        return NCP_KINS_XYZBC_TRT;
    return -1;
}

extern "C" const char *ncp_kins_name(int type)
{
    switch (type) {
    case NCP_KINS_XYZAC_TRT: return "xyzac-trt";
    case NCP_KINS_XYZBC_TRT: return "xyzbc-trt";
    default: return "trivkins";
    }
}

extern "C" int ncp_kins_tilt_axis(int type)
{
    return type == NCP_KINS_XYZAC_TRT ? 3 : type == NCP_KINS_XYZBC_TRT ? 4 : -1;
}

extern "C" void ncp_kins_inverse(const ncp_kins *k, double tool_z,
                                 const double pos[NCP_KINS_JOINTS],
                                 double joint[NCP_KINS_JOINTS])
{
    copy_all(pos, joint);
    if (k->type == NCP_KINS_TRIVIAL)
        return;
    const Trt t = setup(*k, tool_z);
    const Vec3 w(pos[0], pos[1], pos[2]);
    const Vec3 j = t.r + t.d +
                   turn(pos[t.tilt], t.tilt_axis) * (turn(pos[5], Vec3::UnitZ()) * (w - t.r) - t.d);
    joint[0] = j.x();
    joint[1] = j.y();
    joint[2] = j.z();
}

extern "C" void ncp_kins_forward(const ncp_kins *k, double tool_z,
                                 const double joint[NCP_KINS_JOINTS],
                                 double pos[NCP_KINS_JOINTS])
{
    copy_all(joint, pos);
    if (k->type == NCP_KINS_TRIVIAL)
        return;
    const Trt t = setup(*k, tool_z);
    const Vec3 j(joint[0], joint[1], joint[2]);
    const Vec3 w = t.r + turn(-joint[5], Vec3::UnitZ()) *
                             (turn(-joint[t.tilt], t.tilt_axis) * (j - t.r - t.d) + t.d);
    pos[0] = w.x();
    pos[1] = w.y();
    pos[2] = w.z();
}
