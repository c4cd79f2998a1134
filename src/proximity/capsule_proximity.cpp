#include "capsule_proximity.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "point_motion.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {
namespace {

// 2^exponent for -1000 <= exponent <= 1000, from its bits (std::ldexp is a library call, and this
// whole path takes ~50 ns).
double power_of_two(int exponent) {
  const std::uint64_t bits = static_cast<std::uint64_t>(exponent + 1023) << 52;
  double value = 0.0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// e with 2^e <= size < 2^(e + 1), as std::ilogb, for a size >= 2^-1000; false below (zero and
// subnormal sizes included). Validation keeps every length and coordinate within 1e100 (about
// 2^332), so e stays below 334.
bool frame_exponent(double size, int& exponent) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &size, sizeof bits);
  exponent = static_cast<int>(bits >> 52) - 1023;  // size >= 0: no sign bit
  return exponent >= -1000;
}

// A quaternion normalized, q^ = q / |q|, with 1 / |q| and the body x axis
//   u = Q(q^) e_x = [1 - 2 (y^2 + z^2), 2 (x y + w z), 2 (x z - w y)]
// (the first column of unit_quaternion.cpp's Q). Tried: u = A(q) / |q|^2 from the raw q (A the
// same quadratic form), one division and no square root; measured 4 ns slower per query.
struct AxisAttitude {
  Eigen::Vector4d unit;
  double inverse_norm;
  Eigen::Vector3d axis;
};

AxisAttitude axis_attitude(const Eigen::Vector4d& q) {
  // Pose keeps |q| within [1e-40, 2e100], so |q|^2 neither underflows nor overflows.
  const double inverse_norm = 1.0 / std::sqrt(q.squaredNorm());
  const Eigen::Vector4d unit = q * inverse_norm;
  const double w = unit(0), x = unit(1), y = unit(2), z = unit(3);
  return {
      unit, inverse_norm,
      Eigen::Vector3d(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y))};
}

// d(e . Q(q^) e_x) / dq for the q as given: J' e with J = d(Q(q^) e_x) / dq^, whose columns
// (w, x, y, z) are 2 [w z -y]', 2 [x y z]', 2 [-y x -w]', 2 [-z w x]' (valid on the unit sphere,
// where 1 - 2 (y^2 + z^2) = w^2 + x^2 - y^2 - z^2), then the normalization's derivative
// (I - q^ q^') / |q|. The batch kernel (capsule_rows.cpp) uses the same formula per lane.
inline Eigen::Vector4d axis_gradient(const AxisAttitude& q, const Eigen::Vector3d& e) {
  const double w = q.unit(0), x = q.unit(1), y = q.unit(2), z = q.unit(3);
  const Eigen::Vector4d along_unit(
      2.0 * (e.x() * w + e.y() * z - e.z() * y), 2.0 * (e.x() * x + e.y() * y + e.z() * z),
      2.0 * (e.y() * x - e.x() * y - e.z() * w), 2.0 * (e.y() * w + e.z() * x - e.x() * z));
  return (along_unit - q.unit.dot(along_unit) * q.unit) * q.inverse_norm;
}

// The generic case solved in the frame (below), what both results are built from.
struct GenericSolution {
  AxisAttitude attitude_a, attitude_b;
  double scale;         // the frame's power of two
  double s, t;          // the closest points' offsets from the middles along u and v, in the frame
  Eigen::Vector3d n;    // u x v
  double sin2;          // |u x v|^2
  double cos;           // u . v
  bool s_free, t_free;  // s, t strictly inside their segments
  bool edge_normal;     // the normal is the edges' -+(u x v) / |u x v| (fill_proximity)
  Eigen::Vector3d D;    // p1 - p2 in the frame
  double D2;            // |D|^2
};

// In the frame (lengths divided by scale = 2^e, pair_frame.hpp), the capsules' cores are
// P(s) = w + s u and Q(t) = t v about b's middle, w = (r_a - r_b) / scale, s in [-h, h],
// t in [-k, k]. The closest points are segment_segment.cpp's first regime (Ericson's clamping,
// exact for axes this far from parallel), written with the same formulas:
//   s = clamp(-((w x v) . n) / |n|^2, -h, h), n = u x v;  t = f + s cos, f = v . w, cos = u . v;
//   if t leaves [-k, k]: t = clamp(t, -k, k), s = clamp(t cos - c, -h, h), c = u . w.
// False outside the generic case (capsule_proximity.hpp). Forced inline, as fill_proximity: as
// calls, with the solution passed through memory, proximity() took 5 ns (10%) longer.
[[gnu::always_inline]] inline bool solve_generic(const Capsule& a, const Pose& pose_a,
                                                 const Capsule& b, const Pose& pose_b,
                                                 GenericSolution& out) {
  const double length_a = a.length(), length_b = b.length();
  const Eigen::Vector3d offset = pose_a.r() - pose_b.r();
  const double size =
      std::max({length_a, length_b, a.radius(), b.radius(), offset.cwiseAbs().maxCoeff()});
  int exponent = 0;
  if (!frame_exponent(size, exponent)) return false;
  const double scale = power_of_two(exponent), inverse_scale = power_of_two(-exponent);
  const double h = 0.5 * length_a * inverse_scale, k = 0.5 * length_b * inverse_scale;
  if (!(h >= 0x1p-501 && k >= 0x1p-501)) return false;  // each length >= 2^-500 S

  out.attitude_a = axis_attitude(pose_a.q());
  out.attitude_b = axis_attitude(pose_b.q());
  // Component by component: Eigen's 3-vectors in SSE2 pairs spend more on shuffles than on the
  // arithmetic here.
  const Eigen::Vector3d& u = out.attitude_a.axis;
  const Eigen::Vector3d& v = out.attitude_b.axis;
  const double ux = u.x(), uy = u.y(), uz = u.z();
  const double vx = v.x(), vy = v.y(), vz = v.z();
  const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;  // u x v
  const double sin2 = nx * nx + ny * ny + nz * nz;
  if (!(sin2 > 1e-2)) return false;  // within ~5.7 degrees of parallel

  const double wx = offset.x() * inverse_scale, wy = offset.y() * inverse_scale,
               wz = offset.z() * inverse_scale;
  const double c = ux * wx + uy * wy + uz * wz, f = vx * wx + vy * wy + vz * wz,
               cos = ux * vx + uy * vy + uz * vz;
  const double across_n =
      (wy * vz - wz * vy) * nx + (wz * vx - wx * vz) * ny + (wx * vy - wy * vx) * nz;  // (w x v).n
  double s = std::clamp(-across_n / sin2, -h, h);
  const double t_free = f + s * cos;
  const double t = std::clamp(t_free, -k, k);
  // Both candidates computed and one selected: which one applies is a coin toss for random
  // poses, and a mispredicted branch costs more than the few flops.
  const double s_clamped = std::clamp(t * cos - c, -h, h);
  s = t == t_free ? s : s_clamped;

  const Eigen::Vector3d D(wx + s * ux - t * vx, wy + s * uy - t * vy, wz + s * uz - t * vz);
  const double D2 = D.x() * D.x() + D.y() * D.y() + D.z() * D.z();
  // |D| > 1e-2 scale: the frame's size S is below 2 sqrt(3) scale, so D / |D|, with D exact to
  // a few eps S, is exact to ~1e-13 (capsule_proximity.hpp).
  if (!(D2 > 1e-4)) return false;
  out.scale = scale;
  out.s = s, out.t = t;
  out.n = Eigen::Vector3d(nx, ny, nz);
  out.sin2 = sin2, out.cos = cos;
  out.D = D, out.D2 = D2;
  out.s_free = s > -h && s < h;
  out.t_free = t > -k && t < k;
  out.edge_normal = out.s_free && out.t_free && sin2 >= D2;
  return true;
}

// phi = |D|^2 scale^2 - (R_a + R_b)^2 (eq. caps_prox), and by the envelope theorem (eq. dphi;
// s, t optimal) dphi/dr_a = 2 D scale = -dphi/dr_b, and the quaternion parts are
// 2 D . dP/dq_a = axis_gradient(q_a, s 2 D) and -axis_gradient(q_b, t 2 D), times scale^2
// (pair_result.cpp's restore_units). The normal points from a to b: -D / |D|.
[[gnu::always_inline]] inline void fill_proximity(const GenericSolution& g, const Capsule& a,
                                                  const Pose& pose_a, const Capsule& b,
                                                  const Pose& pose_b, Proximity& result) {
  const double scale = g.scale;
  const double radius_sum = a.radius() + b.radius();
  result.phi = g.D2 * scale * scale - radius_sum * radius_sum;
  const Eigen::Vector3d slope = 2.0 * g.D;  // dphi/dD in the frame
  result.gradient.segment<3>(0) = slope * scale;
  // Two products, not scale^2: that underflows below 2^-537 where the gradient does not.
  result.gradient.segment<4>(3) = axis_gradient(g.attitude_a, g.s * slope) * scale * scale;
  result.gradient.segment<3>(7) = -slope * scale;
  result.gradient.segment<4>(10) = -axis_gradient(g.attitude_b, g.t * slope) * scale * scale;
  // The normal by contact_normal.hpp's rule, as the general pipeline takes it: both points
  // inside their segments, D is normal to both axes and the normal is -+(u x v) / |u x v|, exact
  // to ~eps / sin, where D / |D| carries s's rounding, ~eps |w| / (sin^2 |D|) (up to 2e-13 at
  // sin^2 = 1e-2 and |D| = 1e-2: a hostile review measured 1.7e-13); taken where that is the
  // smaller error, sin >= |D|. Otherwise D is exact to a few eps S and D / |D| to eps S / |D|.
  if (g.edge_normal) {
    result.normal = g.n * ((g.n.dot(g.D) > 0.0 ? -1.0 : 1.0) / std::sqrt(g.sin2));
  } else {
    result.normal = g.D * (-1.0 / std::sqrt(g.D2));
  }
  result.cores_intersect = false;
  result.core_points = {pose_a.r() + scale * (g.s * g.attitude_a.axis),
                        pose_b.r() + scale * (g.t * g.attitude_b.axis)};
  result.points = {result.core_points[0] + a.radius() * result.normal,
                   result.core_points[1] - b.radius() * result.normal};  // eqs. caps_c_1, caps_c_2
}

// du/dq for the unit axis u = Q(q^) e_x of the q as given: J(q^) (I - q^ q^') / |q|, with J's
// columns as in axis_gradient; J(q^) q^ = 2 u (J is linear in q^ and u quadratic), so this is
// (J(q^) - 2 u q^') / |q|.
Eigen::Matrix<double, 3, 4> axis_jacobian(const AxisAttitude& q) {
  const double w = q.unit(0), x = q.unit(1), y = q.unit(2), z = q.unit(3);
  Eigen::Matrix<double, 3, 4> J;
  J << w, x, -y, -z,  //
      z, y, x, w,     //
      -y, z, -w, x;
  return (2.0 * J - (2.0 * q.axis) * q.unit.transpose()) * q.inverse_norm;
}

// The closest points' Jacobians in the inputs' units, x = [r_a q_a r_b q_b]. With S = scale s,
// T = scale t, Delta = p1 - p2 = scale D, p1 = r_a + S u(q_a), p2 = r_b + T v(q_b):
//   held S, T: dp1 = [I, S Ju, 0, 0], dp2 = [0, 0, I, T Jv]  (Ju = du/dq_a, Jv = dv/dq_b).
// A free S (strictly inside its segment) keeps u . Delta = 0, a free T keeps v . Delta = 0.
// Differentiating:
//   d(u . Delta) = a + (u . u) dS - cos dT,  a = [u', Delta' Ju + S u' Ju, -u', -T u' Jv],
//   d(v . Delta) = b + cos dS - (v . v) dT,  b = [v', S v' Ju, -v', Delta' Jv - T v' Jv],
// so both free: dS = (cos b - (v . v) a) / sin^2, dT = ((u . u) b - cos a) / sin^2, with
// (u . u)(v . v) - cos^2 = |u x v|^2 = sin^2 (Lagrange's identity, > 1e-2); S alone:
// dS = -a / (u . u); T alone: dT = b / (v . v); neither (two ends): both zero. The computed axes
// are unit only to ~1e-15, so u . u, v . v and u' Ju, v' Jv are kept: taking them as 1 and 0, a
// hostile review measured dS, dT off by ~1e-13 (1 / sin^2 times the axes' rounding). Then
// dp1 += u dS, dp2 += v dT, and the surface points p1 + R_a n, p2 - R_b n move with the normal:
//   the edges' normal n = sign (u x v) / |u x v| (fill_proximity): dn = sign (I - n n')
//     (-[v]x Ju dq_a + [u]x Jv dq_b) / |u x v|, exactly zero along the positions (from
//     (I - n n') (dp2 - dp1) / |Delta| instead, the review found R / |Delta| times dS's rounding,
//     7e-11 at R = 2, |Delta| = 0.01);
//   n = -Delta / |Delta|: dn = (I - n n') (dp2 - dp1) / |Delta|.
// (The implicit function theorem of point_motion.hpp and contact_normal.cpp's normal motion, for
// this one case in closed form.)
inline void fill_jacobians(const GenericSolution& g, const Capsule& a, const Capsule& b,
                           ProximityJacobian& result) {
  using Row = Eigen::Matrix<double, 1, 14>;
  const Eigen::Vector3d& u = g.attitude_a.axis;
  const Eigen::Vector3d& v = g.attitude_b.axis;
  const double S = g.scale * g.s, T = g.scale * g.t;
  const Eigen::Vector3d delta = g.scale * g.D;
  const Eigen::Matrix<double, 3, 4> Ju = axis_jacobian(g.attitude_a);
  const Eigen::Matrix<double, 3, 4> Jv = axis_jacobian(g.attitude_b);
  Row dS = Row::Zero(), dT = Row::Zero();
  if (g.s_free || g.t_free) {
    const double uu = u.squaredNorm(), vv = v.squaredNorm();
    Row a_row, b_row;
    a_row << u.transpose(), (delta + S * u).transpose() * Ju, -u.transpose(),
        -T * (u.transpose() * Jv);
    b_row << v.transpose(), S * (v.transpose() * Ju), -v.transpose(),
        (delta - T * v).transpose() * Jv;
    if (g.s_free && g.t_free) {
      const double inverse_sin2 = 1.0 / g.sin2;
      dS = (g.cos * b_row - vv * a_row) * inverse_sin2;
      dT = (uu * b_row - g.cos * a_row) * inverse_sin2;
    } else if (g.s_free) {
      dS = -a_row / uu;
    } else {
      dT = b_row / vv;
    }
  }
  Matrix3x14 dp1 = u * dS, dp2 = v * dT;
  dp1.block<3, 3>(0, 0) += Eigen::Matrix3d::Identity();
  dp1.block<3, 4>(0, 3) += S * Ju;
  dp2.block<3, 3>(0, 7) += Eigen::Matrix3d::Identity();
  dp2.block<3, 4>(0, 10) += T * Jv;
  const Eigen::Vector3d& n = result.normal;
  Matrix3x14 dn = Matrix3x14::Zero();
  if (g.edge_normal) {
    dn.block<3, 4>(0, 3) = -skew(v) * Ju;  // d(u x v) = du x v + u x dv
    dn.block<3, 4>(0, 10) = skew(u) * Jv;
    const double sign = n.dot(g.n) > 0.0 ? 1.0 : -1.0;
    dn = (dn - n * (n.transpose() * dn)) * (sign / std::sqrt(g.sin2));
  } else {
    dn = (dp2 - dp1 - n * (n.transpose() * (dp2 - dp1))) * (1.0 / (g.scale * std::sqrt(g.D2)));
  }
  result.core_points_jacobian.topRows<3>() = dp1;
  result.core_points_jacobian.bottomRows<3>() = dp2;
  result.points_jacobian.topRows<3>() = dp1 + a.radius() * dn;
  result.points_jacobian.bottomRows<3>() = dp2 - b.radius() * dn;
}

}  // namespace

bool generic_capsule_proximity(const Capsule& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b, Proximity& result) {
  GenericSolution solution;
  if (!solve_generic(a, pose_a, b, pose_b, solution)) return false;
  fill_proximity(solution, a, pose_a, b, pose_b, result);
  return true;
}

bool generic_capsule_proximity_jacobian(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                        const Pose& pose_b, ProximityJacobian& result) {
  GenericSolution solution;
  if (!solve_generic(a, pose_a, b, pose_b, solution)) return false;
  fill_proximity(solution, a, pose_a, b, pose_b, result);
  fill_jacobians(solution, a, b, result);
  return true;
}

}  // namespace diffpills::detail
