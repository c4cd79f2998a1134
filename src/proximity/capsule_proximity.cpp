#include "capsule_proximity.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "symmetric_gram.hpp"
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

// AxisAttitude (capsule_proximity.hpp) of a quaternion q = (w, x, y, z), the body x axis being
//   u = Q(q^) e_x = A(q) / |q|^2,  A(q) = [w^2 + x^2 - y^2 - z^2, 2 (x y + w z), 2 (x z - w y)]
// (the first column of unit_quaternion.cpp's Q, each entry quadratic in q). From the raw q the
// axis takes one division on the way to s, where normalizing q first put a square root and a
// division there. q^ and 1 / |q| (the gradient's, the Jacobians' and the Hessian's) come from the
// same 1 / |q|^2 off that path: they are needed only once the closest points are known. Forced
// inline: as a call, returning the struct through memory, the query took ~3 ns longer
// (BENCHMARKS.md, 2026-11-29).
[[gnu::always_inline]] inline AxisAttitude axis_attitude(const Eigen::Vector4d& q) {
  // Pose keeps |q| within [1e-40, 2e100], so |q|^2 neither underflows nor overflows.
  const double w = q(0), x = q(1), y = q(2), z = q(3);
  const double inverse_norm2 = 1.0 / q.squaredNorm();
  const double inverse_norm = std::sqrt(inverse_norm2);
  const Eigen::Vector3d quadratic(w * w + x * x - y * y - z * z, 2.0 * (x * y + w * z),
                                  2.0 * (x * z - w * y));
  return {q * inverse_norm, inverse_norm, quadratic * inverse_norm2};
}

// Half the derivative of e . u over the unit quaternion q^, projected onto the sphere's tangent
// plane at q^, for the axis u = Q(q^) e_x:
//   T(q^, u, e) = B(q^)' e - (e . u) q^,
//   B(q^)' e = [e_x w + e_y z - e_z y, e_x x + e_y y + e_z z, e_y x - e_x y - e_z w,
//               e_y w + e_z x - e_x z]   (w, x, y, z the components of q^),
// so that for the q as given e . du/dq = (2 / |q|) T.
// Derivation: u = Q(q^) e_x with q^ = q / |q| has du/dq = J(q^) (I - q^ q^') / |q|, where
// J = d(Q(q^) e_x) / dq^ = 2 B(q^) (B's columns (w, x, y, z) are [w z -y]', [x y z]', [-y x -w]',
// [-z w x]', valid on the unit sphere where 1 - 2 (y^2 + z^2) = w^2 + x^2 - y^2 - z^2). B is
// linear and u quadratic in q^, so B(q^) q^ = u and q^ . B(q^)' e = e . u. T is of the size of
// |e| whatever |q| is; the caller multiplies by 2 / |q| with its own factors. (The batch kernel,
// capsule_rows.cpp, takes the same derivative per lane.)
inline Eigen::Vector4d half_tangent_axis_gradient(const Eigen::Vector4d& unit,
                                                  const Eigen::Vector3d& u,
                                                  const Eigen::Vector3d& e) {
  const double w = unit(0), x = unit(1), y = unit(2), z = unit(3);
  const Eigen::Vector4d along(e.x() * w + e.y() * z - e.z() * y, e.x() * x + e.y() * y + e.z() * z,
                              e.y() * x - e.x() * y - e.z() * w, e.y() * w + e.z() * x - e.x() * z);
  return along - e.dot(u) * unit;
}

// In the frame (lengths divided by scale = 2^e, pair_frame.hpp), the capsules' cores are
// P(s) = w + s u and Q(t) = t v about b's middle, w = (r_a - r_b) / scale, s in [-h, h],
// t in [-k, k]. The closest points are segment_segment.cpp's first regime (Ericson's clamping,
// exact for axes this far from parallel), written with the same formulas:
//   s = clamp(-((w x v) . n) / |n|^2, -h, h), n = u x v;  t = f + s cos, f = v . w, cos = u . v;
//   if t leaves [-k, k]: t = clamp(t, -k, k), s = clamp(t cos - c, -h, h), c = u . w.
// False outside the generic case (capsule_proximity.hpp). Forced inline into proximity()'s pass,
// as generic_proximity: as calls, with the solution passed through memory, proximity() took 5 ns
// (10%) longer. The Jacobian and the Hessian get it through memory (solve_generic_capsules), a
// cost they carry easily.
[[gnu::always_inline]] inline bool solve_generic(const Capsule& a, const Pose& pose_a,
                                                 const Capsule& b, const Pose& pose_b,
                                                 GenericCapsuleSolution& out) {
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
  // s for t held at either end (t is then exactly +-k) is computed beside the free s, off its
  // path, so that the held case costs one select at the end of the chain rather than a
  // multiplication, a subtraction and a clamp after t (the query ~7 ns faster, BENCHMARKS.md).
  const double s_for_end = k * cos - c, s_for_start = -k * cos - c, s_star = -across_n / sin2;
  const double s_at_end = std::clamp(s_for_end, -h, h);
  const double s_at_start = std::clamp(s_for_start, -h, h);
  const double s_for_free_t = std::clamp(s_star, -h, h);
  const double t_free = f + s_for_free_t * cos;
  // Ties: a clamp decided by less than 2^-36 of the frame's unit (the quantities clamped err by
  // ~1e-13 of it, in either path; the frame's size is below 2 sqrt(3)). The points barely depend
  // on the side taken, but their Jacobians and phi's Hessian do: they are one-sided there, and a
  // core shorter than the axes' rounding (2e-81 long, 3 away: a finding of fuzz_proximity) is a
  // tie along its whole length. Left to the general pipeline, so that both paths answer a tie
  // the same way. The clamps: s* to [-h, h], t for it to [-k, k], and, when t is held at an
  // end, s for that end to [-h, h].
  const auto near_bound = [](double value, double bound) {
    return std::abs(std::abs(value) - bound) < 0x1p-36;
  };
  if (near_bound(s_star, h) || near_bound(t_free, k) || (t_free > k && near_bound(s_for_end, h)) ||
      (t_free < -k && near_bound(s_for_start, h))) {
    return false;
  }
  const double t = std::clamp(t_free, -k, k);
  const double s = t_free > k ? s_at_end : t_free < -k ? s_at_start : s_for_free_t;

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
// 2 D . s du/dq_a = (4 s / |q_a|) half_tangent_axis_gradient(q_a^, u, D) and
// -2 D . t dv/dq_b = (-4 t / |q_b|) half_tangent_axis_gradient(q_b^, v, D), times scale^2
// (pair_result.cpp's restore_units). The normal points from a to b: -D / |D|.
[[gnu::always_inline]] inline Proximity generic_proximity(const GenericCapsuleSolution& g,
                                                          const Capsule& a, const Pose& pose_a,
                                                          const Capsule& b, const Pose& pose_b) {
  const double scale = g.scale;
  const double radius_sum = a.radius() + b.radius();
  Eigen::Matrix<double, 14, 1> gradient;
  const double twice_scale = 2.0 * scale;
  gradient.segment<3>(0) = g.D * twice_scale;
  gradient.segment<3>(7) = g.D * -twice_scale;
  // The factor 4 s scale^2 / |q| as (4 s scale) (scale / |q|): 4 s scale is the offset in the
  // inputs' units, scale / |q| is 1 / |q| (within [5e-101, 1e40]) times the scale, and either
  // one leaves the normal range only where the entry does (|T| <= |D| < 4 in the frame) or where
  // the closest point is within 2^-1022 (absolute) of the middle. Each product scales by exactly
  // 2^k or 2^2k with the scene, so the gradient does too while every product is a normal number
  // (an entry within a few ulps of 2^-1022 may differ by one). T is of the size of D at any |q|.
  // Two hostile reviews found earlier orders losing entries: |q| T times 4 s / |q|^2 scale scale
  // gave 0 at |q| = 1e100 and s = 1e-150 of a unit scene, where the entry is 2e-250; 4 s / |q|
  // formed first gave 0 at |q| = 1e100 and s = 1e-250 of a 2^330 scene, where it is 3e-151.
  const double factor_a = (4.0 * g.s * scale) * (scale * g.attitude_a.inverse_norm);
  const double factor_b = (-4.0 * g.t * scale) * (scale * g.attitude_b.inverse_norm);
  gradient.segment<4>(3) =
      half_tangent_axis_gradient(g.attitude_a.unit, g.attitude_a.axis, g.D) * factor_a;
  gradient.segment<4>(10) =
      half_tangent_axis_gradient(g.attitude_b.unit, g.attitude_b.axis, g.D) * factor_b;
  // The normal by contact_normal.hpp's rule, as the general pipeline takes it: both points
  // inside their segments, D is normal to both axes and the normal is -+(u x v) / |u x v|, exact
  // to ~eps / sin, where D / |D| carries s's rounding, ~eps |w| / (sin^2 |D|) (up to 2e-13 at
  // sin^2 = 1e-2 and |D| = 1e-2: a hostile review measured 1.7e-13); taken where that is the
  // smaller error, sin >= |D|. Otherwise D is exact to a few eps S and D / |D| to eps S / |D|.
  const Eigen::Vector3d normal =
      g.edge_normal ? Eigen::Vector3d(g.n * ((g.n.dot(g.D) > 0.0 ? -1.0 : 1.0) / std::sqrt(g.sin2)))
                    : Eigen::Vector3d(g.D * (-1.0 / std::sqrt(g.D2)));
  const Eigen::Vector3d core_a = pose_a.r() + (scale * g.s) * g.attitude_a.axis;
  const Eigen::Vector3d core_b = pose_b.r() + (scale * g.t) * g.attitude_b.axis;
  // Every member given: the default member initializers (a zeroed gradient) are not run first.
  return {g.D2 * scale * scale - radius_sum * radius_sum,
          {core_a, core_b},
          {core_a + a.radius() * normal, core_b - b.radius() * normal},  // eqs. caps_c_1, caps_c_2
          normal,
          false,
          gradient};
}

// du/dq for the unit axis u = Q(q^) e_x of the q as given: J(q^) (I - q^ q^') / |q|, with
// J = 2 B as in half_tangent_axis_gradient; J(q^) q^ = 2 u (J is linear in q^ and u quadratic),
// so this is (J(q^) - 2 u q^') / |q|. Row-major: e' du/dq is a sum of three contiguous rows
// (axis_rate).
using AxisJacobian = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;

[[gnu::always_inline]] inline AxisJacobian axis_jacobian(const AxisAttitude& q) {
  const double w = q.unit(0), x = q.unit(1), y = q.unit(2), z = q.unit(3);
  AxisJacobian J;
  J << w, x, -y, -z,  //
      z, y, x, w,     //
      -y, z, -w, x;
  return (2.0 * J - (2.0 * q.axis) * q.unit.transpose()) * q.inverse_norm;
}

// e' du/dq.
[[gnu::always_inline]] inline Eigen::RowVector4d axis_rate(const AxisJacobian& J,
                                                           const Eigen::Vector3d& e) {
  return e.x() * J.row(0) + e.y() * J.row(1) + e.z() * J.row(2);
}

// Both capsules' du/dq_a and dv/dq_b, what the Jacobians and the Hessian start from.
struct AxisJacobians {
  AxisJacobian Ju, Jv;
};

[[gnu::always_inline]] inline AxisJacobians axis_jacobians(const GenericCapsuleSolution& g) {
  return {axis_jacobian(g.attitude_a), axis_jacobian(g.attitude_b)};
}

// d^2 (e . u) / dq^2 for the unit axis u = Q(q^) e_x of the q as given: unit_quaternion.cpp's
// rotate_hessian for the body vector e_x, whose quadratic form e . Q(q^) e_x = q^' M q^ has
//   M = [  e_x   0     -e_z   e_y ]
//       [  0     e_x    e_y   e_z ]
//       [ -e_z   e_y   -e_x   0   ]
//       [  e_y   e_z    0    -e_x ]
// (2 M q^ is J(q^)' e = 2 B(q^)' e, half_tangent_axis_gradient's B). With G = e . u and
//   g = 2 (M q^ - G q^):
//   hess = (2 M - 2 G I - 2 q^ g' - 2 g q^') / |q|^2,
// times `factor`, in units of `scale` twice. 1 / |q| is multiplied by the scale first: 1 / |q|^2
// spans [2.5e-201, 1e80] and scale^2 [2^-2000, 2^666], so either squared alone, or factor / |q|^2
// for a small factor (a short capsule's s), may leave the normal range where the entry does not
// (a hostile review: |q| = 1e100 and s = 1e-25 of a 1e99 scene lost the block); (1 / |q|) scale
// is within the inputs' range, and the bracket is at most a few units, so where f underflows the
// entry does. Each entry below the diagonal is formed once and mirrored, so the block is exactly
// symmetric. G is taken as e . u from the axis this pass already has, where rotate_hessian forms
// q^' M q^ (the same on the unit sphere, to rounding); UnitQuaternion itself needs the full
// rotation matrix and its rotation-vector map, which this pass does not build.
[[gnu::always_inline]] inline Eigen::Matrix4d axis_hessian(const AxisAttitude& q,
                                                           const Eigen::Vector3d& e, double factor,
                                                           double scale) {
  const double w = q.unit(0), x = q.unit(1), y = q.unit(2), z = q.unit(3);
  const double ex = e.x(), ey = e.y(), ez = e.z();
  const double G = e.dot(q.axis);
  const double gw = 2.0 * (ex * w - ez * y + ey * z - G * w);
  const double gx = 2.0 * (ex * x + ey * y + ez * z - G * x);
  const double gy = 2.0 * (ey * x - ez * w - ex * y - G * y);
  const double gz = 2.0 * (ey * w + ez * x - ex * z - G * z);
  const double unit = q.inverse_norm * scale;  // 1 / |q| in the frame's lengths
  const double f = 2.0 * factor * unit * unit;
  const auto entry = [f](double m, double qi, double gj, double gi, double qj) {
    return f * (m - qi * gj - gi * qj);
  };
  const double ww = entry(ex - G, w, gw, gw, w), xw = entry(0.0, x, gw, gx, w),
               yw = entry(-ez, y, gw, gy, w), zw = entry(ey, z, gw, gz, w),
               xx = entry(ex - G, x, gx, gx, x), yx = entry(ey, y, gx, gy, x),
               zx = entry(ez, z, gx, gz, x), yy = entry(-ex - G, y, gy, gy, y),
               zy = entry(0.0, z, gy, gz, y), zz = entry(-ex - G, z, gz, gz, z);
  Eigen::Matrix4d hessian;
  hessian << ww, xw, yw, zw,  //
      xw, xx, yx, zx,         //
      yw, yx, yy, zy,         //
      zw, zx, zy, zz;
  return hessian;
}

// Translating both capsules together moves nothing but the points, so phi and D depend on the
// positions only through w = r_a - r_b. The derivatives below are taken over the 11 coordinates
// y = [w q_a q_b] in the frame (w / scale), and spread over x = [r_a q_a r_b q_b] when written
// (d/dr_a = d/dw, d/dr_b = -d/dw), the quaternion columns multiplied by scale.
using ReducedRow = Eigen::Matrix<double, 1, 11>;

// The rates a and b below (free_motion's) have quaternion parts e' Ju and e' Jv for the vectors e
// here.
struct RateVectors {
  Eigen::Vector3d a_qa, a_qb, b_qa, b_qb;
};

[[gnu::always_inline]] inline RateVectors rate_vectors(const GenericCapsuleSolution& g) {
  const Eigen::Vector3d& u = g.attitude_a.axis;
  const Eigen::Vector3d& v = g.attitude_b.axis;
  return {g.D + g.s * u, -g.t * u, g.s * v, g.D - g.t * v};
}

// How the free coordinates move. With D = w + s u(q_a) - t v(q_b), a free s (strictly inside its
// segment) keeps u . D = 0 and a free t keeps v . D = 0. Differentiating,
//   d(u . D) = a + (u . u) ds - cos dt,  a = [u', (D + s u)' Ju, -t u' Jv],
//   d(v . D) = b + cos ds - (v . v) dt,  b = [v', s v' Ju, (D - t v)' Jv]
// (Ju = du/dq_a, Jv = dv/dq_b), so both free: ds = (cos b - (v . v) a) / sin^2,
// dt = ((u . u) b - cos a) / sin^2, with (u . u)(v . v) - cos^2 = |u x v|^2 = sin^2 (Lagrange's
// identity, > 1e-2); s alone: ds = -a / (u . u); t alone: dt = b / (v . v); neither (two ends):
// both zero. The computed axes are unit only to ~1e-15, so u . u, v . v and u' Ju, v' Jv are
// kept: taking them as 1 and 0, a hostile review measured ds, dt off by ~1e-13 (1 / sin^2 times
// the axes' rounding). (The implicit function theorem of point_motion.hpp for this case in
// closed form.)
struct FreeMotion {
  ReducedRow ds, dt;  // ds/dy, dt/dy
};

[[gnu::always_inline]] inline FreeMotion free_motion(const GenericCapsuleSolution& g,
                                                     const AxisJacobians& J) {
  const Eigen::Vector3d& u = g.attitude_a.axis;
  const Eigen::Vector3d& v = g.attitude_b.axis;
  struct {
    ReducedRow a, b;  // d(u . D)/dy and d(v . D)/dy with s and t held
  } r;
  const RateVectors e = rate_vectors(g);
  r.a << u.transpose(), axis_rate(J.Ju, e.a_qa), axis_rate(J.Jv, e.a_qb);
  r.b << v.transpose(), axis_rate(J.Ju, e.b_qa), axis_rate(J.Jv, e.b_qb);
  // Every case's ds and dt as combinations of a and b, the case choosing four scalars only. Rows
  // set to zero in some branches were cleared with `rep stos`, a slow start for 88 bytes: ~17%
  // of the function's samples fell next to it (perf), and without it the Jacobian took 161-175
  // ns instead of 169-178 (5 paired rounds, BENCHMARKS.md 2026-11-29).
  double ds_a = 0.0, ds_b = 0.0, dt_a = 0.0, dt_b = 0.0;
  if (g.s_free && g.t_free) {
    const double inverse_sin2 = 1.0 / g.sin2;
    ds_a = -v.squaredNorm() * inverse_sin2;
    ds_b = g.cos * inverse_sin2;
    dt_a = -g.cos * inverse_sin2;
    dt_b = u.squaredNorm() * inverse_sin2;
  } else if (g.s_free) {
    ds_a = -1.0 / u.squaredNorm();
  } else if (g.t_free) {
    dt_b = 1.0 / v.squaredNorm();
  }
  return {ds_a * r.a + ds_b * r.b, dt_a * r.a + dt_b * r.b};
}

// A 6 x 11 Jacobian of two points over y, in the frame (positions unitless, quaternions in frame
// lengths), written over x in the inputs' units. Each point also moves with its own body's
// position one for one, what `F` leaves out: d/dr_a = F_w + [I; 0], d/dr_b = -F_w + [0; I].
inline Eigen::Matrix<double, 6, 14> point_columns(const Eigen::Matrix<double, 6, 11>& F,
                                                  double scale) {
  Eigen::Matrix<double, 6, 14> out;
  out.leftCols<3>() = F.leftCols<3>();
  out.block<6, 4>(0, 3) = F.middleCols<4>(3) * scale;
  out.block<6, 3>(0, 7) = -F.leftCols<3>();
  out.rightCols<4>() = F.rightCols<4>() * scale;
  for (int i = 0; i < 3; ++i) {
    out(i, i) += 1.0;
    out(3 + i, 7 + i) += 1.0;
  }
  return out;
}

// The closest points' Jacobians over y in the frame. With s, t held, p1 moves by s Ju along q_a,
// p2 by t Jv along q_b; the free coordinates add u ds and v dt. The surface points p1 + R_a n,
// p2 - R_b n move with the normal too:
//   the edges' normal n = sign (u x v) / |u x v| (generic_proximity): dn = sign (I - n n')
//     [0, -[v]x Ju, [u]x Jv] / |u x v|, exactly zero along the positions (from
//     (I - n n') (dp2 - dp1) / |Delta| instead, the review found R / |Delta| times ds's rounding,
//     7e-11 at R = 2, |Delta| = 0.01);
//   n = -D / |D|: dn = -(I - n n') dD / |D|, dD = dp1 - dp2 (its w columns plus the identity).
// Radii enter the frame as R / scale (below 2: the scene bounds them). (contact_normal.cpp's
// normal motion, in closed form.)
struct PointsMotion {
  Eigen::Matrix<double, 6, 11> core, surface;  // d[p1; p2]/dy and d[p1 + R_a n; p2 - R_b n]/dy
};

[[gnu::always_inline]] inline PointsMotion points_motion(const GenericCapsuleSolution& g,
                                                         const AxisJacobians& J, const Capsule& a,
                                                         const Capsule& b,
                                                         const Eigen::Vector3d& n) {
  const Eigen::Vector3d& u = g.attitude_a.axis;
  const Eigen::Vector3d& v = g.attitude_b.axis;
  const FreeMotion m = free_motion(g, J);
  PointsMotion motion;
  Eigen::Matrix<double, 6, 11>& core = motion.core;
  core.topRows<3>() = u * m.ds;
  core.block<3, 4>(0, 3) += g.s * J.Ju;
  core.bottomRows<3>() = v * m.dt;
  core.block<3, 4>(3, 7) += g.t * J.Jv;
  Eigen::Matrix<double, 3, 11> dn;
  if (g.edge_normal) {
    dn.leftCols<3>().setZero();
    dn.middleCols<4>(3) = -skew(v) * J.Ju;  // d(u x v) = du x v + u x dv
    dn.rightCols<4>() = skew(u) * J.Jv;
    const double sign = n.dot(g.n) > 0.0 ? 1.0 : -1.0;
    dn = (dn - n * (n.transpose() * dn)) * (sign / std::sqrt(g.sin2));
  } else {
    Eigen::Matrix<double, 3, 11> dD = core.topRows<3>() - core.bottomRows<3>();
    dD.leftCols<3>() += Eigen::Matrix3d::Identity();
    dn = (dD - n * (n.transpose() * dD)) * (-1.0 / std::sqrt(g.D2));
  }
  motion.surface.topRows<3>() = core.topRows<3>() + (a.radius() / g.scale) * dn;
  motion.surface.bottomRows<3>() = core.bottomRows<3>() - (b.radius() / g.scale) * dn;
  return motion;
}

// phi's Hessian: phi_hessian.hpp's second-order implicit function theorem for this case in
// closed form. With f = |D|^2 minimized over the free coordinates xi (s, t where free), and
// E = dD/dy with s, t held = [I, s Ju, -t Jv]:
//   H = f_yy + f_y,xi dxi/dy,
//   f_yy / 2 = E'E + blockdiag(0, s hess_qa (D . u), -t hess_qb (D . v))   (D held),
//   f_y,xi dxi/dy / 2 = a ds' - b dt'   (f_xi = 2 [u . D, -v . D], whose y rates are 2 a, -2 b).
// The last term is a negative semidefinite form of rank at most two in a and b. Both free, by
// free_motion's ds and dt it is -(vv a a' - cos (a b' + b a') + uu b b') / sin^2 (uu = u . u,
// vv = v . v), and completing the square with sin^2 = uu vv - cos^2 (Lagrange's identity),
//   -(c1 c1' + c2 c2'),  c1 = (a - (cos / vv) b) sqrt(vv / sin^2),  c2 = b / sqrt(vv);
// s alone it is -a a' / uu (c1 = a / sqrt(uu)), t alone -b b' / vv (c1 = b / sqrt(vv)), at two
// ends 0. So H = 2 (E'E - C'C) plus the two axis Hessians, with C the rows c1, c2: a Gram matrix
// of at most five rows, which symmetric_gram.hpp forms in vector registers, exactly symmetric.
// Each row's quaternion parts are e' Ju and e' Jv for one vector e each (a and b are linear in
// the vectors D + s u, s v, -t u, D - t v, and c1, c2 combinations of them), so no row over y
// is formed first. (Written with ds and dt, entry by entry over the lower triangle, it took
// ~115 ns of the ~260 ns query; BENCHMARKS.md.)
// The rows are spread over x = [r_a q_a r_b q_b] before the product: d/dr_a = d/dw,
// d/dr_b = -d/dw, and the quaternion entries are multiplied by scale, so that each product
// carries the inputs' units (r-r entries none, r-q one scale, q-q two, one product each: scale^2
// alone is subnormal below 2^-511), and H is written in place with no spreading afterwards.
inline Eigen::Matrix<double, 14, 14> capsule_phi_hessian(const GenericCapsuleSolution& g,
                                                         const AxisJacobians& J) {
  const double scale = g.scale;
  // The row over x whose parts over y = [w q_a q_b] are [w, qa, qb].
  const auto set_row = [scale](double* row, const Eigen::Vector3d& w, const Eigen::RowVector4d& qa,
                               const Eigen::RowVector4d& qb) {
    for (int i = 0; i < 3; ++i) {
      row[i] = w(i);
      row[7 + i] = -w(i);
    }
    for (int i = 0; i < 4; ++i) {
      row[3 + i] = qa(i) * scale;
      row[10 + i] = qb(i) * scale;
    }
    row[14] = row[15] = 0.0;
  };
  // ... and [w, e_a' Ju, e_b' Jv].
  const auto set_rate_row = [&](double* row, const Eigen::Vector3d& w, const Eigen::Vector3d& e_a,
                                const Eigen::Vector3d& e_b) {
    set_row(row, w, axis_rate(J.Ju, e_a), axis_rate(J.Jv, e_b));
  };
  const Eigen::Vector3d& u = g.attitude_a.axis;
  const Eigen::Vector3d& v = g.attitude_b.axis;
  GramRows rows;
  for (int k = 0; k < 3; ++k) {  // E's rows
    set_row(rows.plus[k], Eigen::Vector3d::Unit(k), g.s * J.Ju.row(k), -g.t * J.Jv.row(k));
  }
  const auto [a_qa, a_qb, b_qa, b_qb] = rate_vectors(g);
  if (g.s_free && g.t_free) {
    const double vv = v.squaredNorm(), root_vv = std::sqrt(vv);
    const double ratio = g.cos / vv, c1_factor = root_vv / std::sqrt(g.sin2);
    set_rate_row(rows.minus[0], (u - ratio * v) * c1_factor, (a_qa - ratio * b_qa) * c1_factor,
                 (a_qb - ratio * b_qb) * c1_factor);
    set_rate_row(rows.minus[1], v / root_vv, b_qa / root_vv, b_qb / root_vv);
    rows.minus_count = 2;
  } else if (g.s_free) {
    const double root_uu = std::sqrt(u.squaredNorm());
    set_rate_row(rows.minus[0], u / root_uu, a_qa / root_uu, a_qb / root_uu);
    rows.minus_count = 1;
  } else if (g.t_free) {
    const double root_vv = std::sqrt(v.squaredNorm());
    set_rate_row(rows.minus[0], v / root_vv, b_qa / root_vv, b_qb / root_vv);
    rows.minus_count = 1;
  } else {
    rows.minus_count = 0;
  }
  // 2 f_yy's axis blocks, q-q entries: in units of scale twice. Formed before the Gram's call,
  // not after it, so that their scalar arithmetic does not wait on it (proximity_with_hessian
  // 165-166 -> 154-157 ns in a paired run on an Intel Xeon, the same bits; BENCHMARKS.md).
  const Eigen::Matrix4d block_a = axis_hessian(g.attitude_a, g.D, 2.0 * g.s, scale);
  const Eigen::Matrix4d block_b = axis_hessian(g.attitude_b, g.D, -2.0 * g.t, scale);
  Eigen::Matrix<double, 14, 14> H;
  symmetric_gram(rows, H.data());
  H.block<4, 4>(3, 3) += block_a;
  H.block<4, 4>(10, 10) += block_b;
  return H;
}

// generic_proximity as a call of its own, for the Jacobian and the Hessian. Inlined there (as it
// is into proximity(), where it is all the work), it competed with the points' motion for
// registers: in a paired measurement on a Zen 5 the Jacobian took 192-195 ns inlined and 177-181
// ns with this call, the Hessian 261-263 and 244-253 ns, with the same bits (2-6% and 1-3% on an
// Intel Xeon, BENCHMARKS.md 2026-11-29).
[[gnu::noinline]] Proximity generic_proximity_outlined(const GenericCapsuleSolution& g,
                                                       const Capsule& a, const Pose& pose_a,
                                                       const Capsule& b, const Pose& pose_b) {
  return generic_proximity(g, a, pose_a, b, pose_b);
}

}  // namespace

Proximity generic_capsule_proximity(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                    const Pose& pose_b, GeneralCapsuleProximity general) {
  GenericCapsuleSolution solution;
  if (!solve_generic(a, pose_a, b, pose_b, solution)) return general(a, pose_a, b, pose_b);
  return generic_proximity(solution, a, pose_a, b, pose_b);
}

bool solve_generic_capsules(const Capsule& a, const Pose& pose_a, const Capsule& b,
                            const Pose& pose_b, GenericCapsuleSolution& solution) {
  return solve_generic(a, pose_a, b, pose_b, solution);
}

// The Jacobian's and the Hessians' first steps are written out in each: gathered in one helper
// returning a struct of them, the points' motion was copied into it, and the Jacobian took 181 ns
// instead of 159.
ProximityJacobian generic_capsule_proximity_jacobian(const GenericCapsuleSolution& solution,
                                                     const Capsule& a, const Pose& pose_a,
                                                     const Capsule& b, const Pose& pose_b) {
  // The axes' Jacobians first: they need the quaternions alone, not s, t or D, so the processor
  // can form them while the solve's last steps are in flight (in a paired run 181-188 -> 171-182
  // ns, BENCHMARKS.md 2026-11-29).
  const AxisJacobians jacobians = axis_jacobians(solution);
  const Proximity first = generic_proximity_outlined(solution, a, pose_a, b, pose_b);
  const PointsMotion motion = points_motion(solution, jacobians, a, b, first.normal);
  return {first, point_columns(motion.core, solution.scale),
          point_columns(motion.surface, solution.scale)};
}

ProximityHessian generic_capsule_proximity_hessian(const GenericCapsuleSolution& solution,
                                                   const Capsule& a, const Pose& pose_a,
                                                   const Capsule& b, const Pose& pose_b) {
  const Proximity first = generic_proximity_outlined(solution, a, pose_a, b, pose_b);
  const AxisJacobians jacobians = axis_jacobians(solution);
  const PointsMotion motion = points_motion(solution, jacobians, a, b, first.normal);
  return {{first, point_columns(motion.core, solution.scale),
           point_columns(motion.surface, solution.scale)},
          capsule_phi_hessian(solution, jacobians)};
}

ProximityWithHessian generic_capsule_proximity_with_hessian(const GenericCapsuleSolution& solution,
                                                            const Capsule& a, const Pose& pose_a,
                                                            const Capsule& b, const Pose& pose_b) {
  return {generic_proximity(solution, a, pose_a, b, pose_b),
          capsule_phi_hessian(solution, axis_jacobians(solution))};
}

}  // namespace diffpills::detail
