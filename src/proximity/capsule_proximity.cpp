#include "capsule_proximity.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

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

}  // namespace

// In the frame (lengths divided by scale = 2^e, pair_frame.hpp), the capsules' cores are
// P(s) = w + s u and Q(t) = t v about b's middle, w = (r_a - r_b) / scale, s in [-h, h],
// t in [-k, k]. The closest points are segment_segment.cpp's first regime (Ericson's clamping,
// exact for axes this far from parallel), written with the same formulas:
//   s = clamp(-((w x v) . n) / |n|^2, -h, h), n = u x v;  t = f + s cos, f = v . w, cos = u . v;
//   if t leaves [-k, k]: t = clamp(t, -k, k), s = clamp(t cos - c, -h, h), c = u . w.
// With D = P(s) - Q(t), phi = |D|^2 scale^2 - (R_a + R_b)^2 (eq. caps_prox), and by the envelope
// theorem (eq. dphi; s, t optimal) dphi/dr_a = 2 D scale = -dphi/dr_b, and the quaternion parts
// are 2 D . dP/dq_a = axis_gradient(q_a, s 2 D) and -axis_gradient(q_b, t 2 D), times scale^2
// (pair_result.cpp's restore_units). The normal points from a to b: -D / |D|.
bool generic_capsule_proximity(const Capsule& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b, Proximity& result) {
  const double length_a = a.length(), length_b = b.length();
  const Eigen::Vector3d offset = pose_a.r() - pose_b.r();
  const double size =
      std::max({length_a, length_b, a.radius(), b.radius(), offset.cwiseAbs().maxCoeff()});
  int exponent = 0;
  if (!frame_exponent(size, exponent)) return false;
  const double scale = power_of_two(exponent), inverse_scale = power_of_two(-exponent);
  const double h = 0.5 * length_a * inverse_scale, k = 0.5 * length_b * inverse_scale;
  if (!(h >= 0x1p-501 && k >= 0x1p-501)) return false;  // each length >= 2^-500 S

  const AxisAttitude attitude_a = axis_attitude(pose_a.q());
  const AxisAttitude attitude_b = axis_attitude(pose_b.q());
  // Component by component: Eigen's 3-vectors in SSE2 pairs spend more on shuffles than on the
  // arithmetic here.
  const double ux = attitude_a.axis.x(), uy = attitude_a.axis.y(), uz = attitude_a.axis.z();
  const double vx = attitude_b.axis.x(), vy = attitude_b.axis.y(), vz = attitude_b.axis.z();
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
  const Eigen::Vector3d& u = attitude_a.axis;
  const Eigen::Vector3d& v = attitude_b.axis;

  const double radius_sum = a.radius() + b.radius();
  result.phi = D2 * scale * scale - radius_sum * radius_sum;
  const Eigen::Vector3d slope = 2.0 * D;  // dphi/dD in the frame
  result.gradient.segment<3>(0) = slope * scale;
  result.gradient.segment<4>(3) = axis_gradient(attitude_a, s * slope) * (scale * scale);
  result.gradient.segment<3>(7) = -slope * scale;
  result.gradient.segment<4>(10) = -axis_gradient(attitude_b, t * slope) * (scale * scale);
  result.normal = D * (-1.0 / std::sqrt(D2));
  result.cores_intersect = false;
  result.core_points = {pose_a.r() + scale * (s * u), pose_b.r() + scale * (t * v)};
  result.points = {result.core_points[0] + a.radius() * result.normal,
                   result.core_points[1] - b.radius() * result.normal};  // eqs. caps_c_1, caps_c_2
  return true;
}

}  // namespace diffpills::detail
