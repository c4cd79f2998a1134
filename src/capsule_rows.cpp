// Compiled once per instruction set by Highway's foreach_target (this file includes itself through
// HWY_TARGET_INCLUDE); the code outside HWY_NAMESPACE is compiled once (HWY_ONCE).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "capsule_rows.cpp"
#include "capsule_rows.hpp"

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <initializer_list>

HWY_BEFORE_NAMESPACE();
namespace diffpills::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;

// The widest vector of any target (AVX-512: 8 doubles) sizes the chunk's staging arrays.
constexpr int kMaxLanes = HWY_MAX_BYTES / sizeof(double);

struct Quaternion {
  V w, x, y, z;
  V inverse_norm;  // 1 / |q| of the input
};

HWY_INLINE V squared_norm(V w, V x, V y, V z) {
  return hn::MulAdd(w, w, hn::MulAdd(x, x, hn::MulAdd(y, y, z * z)));
}

// q / |q| and 1 / |q| from |q|^2 (one square root, one division per lane).
HWY_INLINE Quaternion normalized(V w, V x, V y, V z, V norm2) {
  const D d;
  const V inverse = hn::Set(d, 1.0) / hn::Sqrt(norm2);
  return {w * inverse, x * inverse, y * inverse, z * inverse, inverse};
}

// The body x axis in the world, Q(q) e_x = [w^2 + x^2 - y^2 - z^2, 2 (x y + w z), 2 (x z - w y)].
HWY_INLINE void axis(const Quaternion& q, V& ux, V& uy, V& uz) {
  const D d;
  const V two = hn::Set(d, 2.0);
  ux = hn::MulAdd(q.w, q.w, q.x * q.x) - hn::MulAdd(q.y, q.y, q.z * q.z);
  uy = two * hn::MulAdd(q.x, q.y, q.w * q.z);
  uz = two * hn::MulSub(q.x, q.z, q.w * q.y);
}

// dvalue/dq for a point p = r + s Q(q^) e_x of a segment, q^ = q / |q|, given e = s dvalue/dp:
//   dvalue/dq^ = J' e with J = d(Q(q^) e_x)/dq^, whose columns (w, x, y, z) are
//   2 [w z -y]', 2 [x y z]', 2 [-y x -w]', 2 [-z w x]' (the derivatives of axis() above), and
//   dvalue/dq = (I - q^ q^') dvalue/dq^ / |q|, the normalization's derivative.
HWY_INLINE void quaternion_gradient(const Quaternion& q, V ex, V ey, V ez, V* out) {
  const D d;
  const V two = hn::Set(d, 2.0);
  const V gw = two * hn::MulAdd(ex, q.w, hn::MulSub(ey, q.z, ez * q.y));
  const V gx = two * hn::MulAdd(ex, q.x, hn::MulAdd(ey, q.y, ez * q.z));
  const V gy = two * hn::MulSub(ey, q.x, hn::MulAdd(ex, q.y, ez * q.w));
  const V gz = two * hn::MulAdd(ey, q.w, hn::MulSub(ez, q.x, ex * q.z));
  const V along = hn::MulAdd(q.w, gw, hn::MulAdd(q.x, gx, hn::MulAdd(q.y, gy, q.z * gz)));
  out[0] = hn::NegMulAdd(q.w, along, gw) * q.inverse_norm;
  out[1] = hn::NegMulAdd(q.x, along, gx) * q.inverse_norm;
  out[2] = hn::NegMulAdd(q.y, along, gy) * q.inverse_norm;
  out[3] = hn::NegMulAdd(q.z, along, gz) * q.inverse_norm;
}

HWY_INLINE V clamp(V value, V low, V high) { return hn::Min(hn::Max(value, low), high); }

// One chunk of Lanes(d) pose pairs, staged as columns: in[k][lane] for the 14 inputs
// [r_a q_a r_b q_b]; out[0][lane] is the value, out[1 + k][lane] the gradient, answered[lane] is
// nonzero where the lane is the generic case (capsule_rows.hpp).
//
// The segment pair is the scalar path's Ericson regime (segment_segment.cpp), with the capsules'
// middles at r (P(s) = r_a + s u, Q(t) = r_b + t v, s in [-h, h], t in [-k, k]):
//   w = r_a - r_b, c = u.w, f = v.w, cos = u.v, n = u x v,
//   s = clamp(-((w x v) . n) / |n|^2, -h, h), t = f + s cos;
//   if t leaves [-k, k]: t = clamp(t, -k, k), s = clamp(t cos - c, -h, h).
// The difference of the closest points D = w + s u - t v gives phi = |D|^2 - (R_a + R_b)^2
// (eq. phi), and by the envelope theorem (s, t optimal; eq. dphi) dphi/dr_a = 2 D = -dphi/dr_b,
// and the quaternion parts from quaternion_gradient with e = s (2 D) for a, t (-2 D) for b.
// The signed distance of separated cores is |D| - (R_a + R_b); its gradient is phi's divided by
// 2 |D|.
HWY_INLINE void chunk(const CapsulePair& pair, const double (*in)[kMaxLanes],
                      double (*out)[kMaxLanes], double* answered) {
  const D d;
  const auto load = [&](int k) { return hn::LoadU(d, in[k]); };
  const V rax = load(0), ray = load(1), raz = load(2);
  const V rbx = load(7), rby = load(8), rbz = load(9);
  const V qaw = load(3), qax = load(4), qay = load(5), qaz = load(6);
  const V qbw = load(10), qbx = load(11), qby = load(12), qbz = load(13);

  // The generic case's inputs (capsule_rows.hpp); false for NaN and infinity too.
  const V position_limit = hn::Set(d, 0x1p40);
  auto generic = hn::Le(hn::Abs(rax), position_limit);
  for (const V& r : {ray, raz, rbx, rby, rbz}) {
    generic = hn::And(generic, hn::Le(hn::Abs(r), position_limit));
  }
  const V norm2_a = squared_norm(qaw, qax, qay, qaz), norm2_b = squared_norm(qbw, qbx, qby, qbz);
  for (const V& norm2 : {norm2_a, norm2_b}) {
    generic = hn::And(
        generic, hn::And(hn::Ge(norm2, hn::Set(d, 0x1p-60)), hn::Le(norm2, hn::Set(d, 0x1p60))));
  }

  const Quaternion qa = normalized(qaw, qax, qay, qaz, norm2_a);
  const Quaternion qb = normalized(qbw, qbx, qby, qbz, norm2_b);
  V ux, uy, uz, vx, vy, vz;
  axis(qa, ux, uy, uz);
  axis(qb, vx, vy, vz);
  const V wx = rax - rbx, wy = ray - rby, wz = raz - rbz;
  const V c = hn::MulAdd(ux, wx, hn::MulAdd(uy, wy, uz * wz));
  const V f = hn::MulAdd(vx, wx, hn::MulAdd(vy, wy, vz * wz));
  const V cos = hn::MulAdd(ux, vx, hn::MulAdd(uy, vy, uz * vz));
  const V nx = hn::MulSub(uy, vz, uz * vy), ny = hn::MulSub(uz, vx, ux * vz),
          nz = hn::MulSub(ux, vy, uy * vx);
  const V sin2 = hn::MulAdd(nx, nx, hn::MulAdd(ny, ny, nz * nz));
  generic = hn::And(generic, hn::Gt(sin2, hn::Set(d, 1e-2)));  // capsule_rows.hpp
  const V across_x = hn::MulSub(wy, vz, wz * vy), across_y = hn::MulSub(wz, vx, wx * vz),
          across_z = hn::MulSub(wx, vy, wy * vx);  // w x v
  const V h = hn::Set(d, 0.5 * pair.length_a), k = hn::Set(d, 0.5 * pair.length_b);
  const V s_star =
      hn::Neg(hn::MulAdd(across_x, nx, hn::MulAdd(across_y, ny, across_z * nz))) / sin2;
  V s = clamp(s_star, hn::Neg(h), h);
  const V t_free = hn::MulAdd(s, cos, f);
  const V t = clamp(t_free, hn::Neg(k), k);
  s = hn::IfThenElse(hn::Eq(t, t_free), s, clamp(hn::MulSub(t, cos, c), hn::Neg(h), h));

  const V Dx = hn::NegMulAdd(t, vx, hn::MulAdd(s, ux, wx));
  const V Dy = hn::NegMulAdd(t, vy, hn::MulAdd(s, uy, wy));
  const V Dz = hn::NegMulAdd(t, vz, hn::MulAdd(s, uz, wz));
  const V D2 = hn::MulAdd(Dx, Dx, hn::MulAdd(Dy, Dy, Dz * Dz));
  const double radii = pair.radius_a + pair.radius_b;
  const V radii_v = hn::Set(d, radii);
  // Cores within 1e-9 of the scene's size are the scalar path's (intersection, penetration).
  // D = w + s u - t v cancels to a few eps S, so it is exact enough for phi's gradient 2 D (eps S
  // absolutely), but the signed distance's gradient direction D / |D| errs by ~eps S / |D|: its
  // rows need |D| > 1e-2 S to stay within 1e-12 (a hostile review measured 4e-8 at 1e-8 S).
  const double gap2 = pair.measure == CapsuleMeasure::kPhi ? 1e-18 : 1e-4;
  const V scene2 =
      hn::Set(d, pair.length_a * pair.length_a + pair.length_b * pair.length_b + radii * radii) +
      hn::MulAdd(wx, wx, hn::MulAdd(wy, wy, wz * wz));
  generic = hn::And(generic, hn::Gt(D2, hn::Set(d, gap2) * scene2));

  // dvalue/dD = 2 D for phi, D / |D| for the signed distance.
  V value, slope;
  if (pair.measure == CapsuleMeasure::kPhi) {
    value = hn::NegMulAdd(radii_v, radii_v, D2);
    slope = hn::Set(d, 2.0);
  } else {
    const V length = hn::Sqrt(D2);
    value = length - radii_v;
    slope = hn::Set(d, 1.0) / length;
  }
  const V gx = slope * Dx, gy = slope * Dy, gz = slope * Dz;
  hn::StoreU(value, d, out[0]);
  hn::StoreU(gx, d, out[1]);
  hn::StoreU(gy, d, out[2]);
  hn::StoreU(gz, d, out[3]);
  hn::StoreU(hn::Neg(gx), d, out[8]);
  hn::StoreU(hn::Neg(gy), d, out[9]);
  hn::StoreU(hn::Neg(gz), d, out[10]);
  V turn[4];
  quaternion_gradient(qa, s * gx, s * gy, s * gz, turn);  // dvalue/dp_a = g
  for (int j = 0; j < 4; ++j) hn::StoreU(turn[j], d, out[4 + j]);
  const V minus_t = hn::Neg(t);  // dvalue/dp_b = -g
  quaternion_gradient(qb, minus_t * gx, minus_t * gy, minus_t * gz, turn);
  for (int j = 0; j < 4; ++j) hn::StoreU(turn[j], d, out[11 + j]);
  hn::StoreU(hn::VecFromMask(d, generic), d, answered);
}

void CapsuleRows(const CapsulePair& pair, const Eigen::Ref<const PositionArray>& r_a,
                 const Eigen::Ref<const QuaternionArray>& q_a,
                 const Eigen::Ref<const PositionArray>& r_b,
                 const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Index begin, Eigen::Index end,
                 Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<GradientArray> gradient,
                 std::uint8_t* left) {
  const D d;
  const Eigen::Index lanes = static_cast<Eigen::Index>(hn::Lanes(d));
  HWY_ALIGN double in[14][kMaxLanes];
  HWY_ALIGN double out[15][kMaxLanes];
  HWY_ALIGN double answered[kMaxLanes];
  for (Eigen::Index first = begin; first < end; first += lanes) {
    const Eigen::Index count = std::min(lanes, end - first);
    // A short last chunk repeats its first row in the unused lanes (answered, never written).
    for (Eigen::Index lane = 0; lane < lanes; ++lane) {
      const Eigen::Index row = first + (lane < count ? lane : 0);
      for (int j = 0; j < 3; ++j) {
        in[j][lane] = r_a(row, j);
        in[7 + j][lane] = r_b(row, j);
      }
      for (int j = 0; j < 4; ++j) {
        in[3 + j][lane] = q_a(row, j);
        in[10 + j][lane] = q_b(row, j);
      }
    }
    chunk(pair, in, out, answered);
    for (Eigen::Index lane = 0; lane < count; ++lane) {
      const Eigen::Index row = first + lane;
      const bool generic = answered[lane] != 0.0;
      left[row - begin] = generic ? 0 : 1;
      if (!generic) continue;
      value(row) = out[0][lane];
      for (int j = 0; j < 14; ++j) gradient(row, j) = out[1 + j][lane];
    }
  }
}

const char* CapsuleRowsTarget() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace diffpills::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace diffpills::detail {

HWY_EXPORT(CapsuleRows);
HWY_EXPORT(CapsuleRowsTarget);

const char* capsule_rows_target() { return HWY_DYNAMIC_DISPATCH(CapsuleRowsTarget)(); }

bool capsule_rows_apply(const CapsulePair& pair) {
  const auto length_in_range = [](double length) { return length >= 0x1p-40 && length <= 0x1p40; };
  return length_in_range(pair.length_a) && length_in_range(pair.length_b) &&
         pair.radius_a <= 0x1p40 && pair.radius_b <= 0x1p40;
}

void capsule_rows(const CapsulePair& pair, const Eigen::Ref<const PositionArray>& r_a,
                  const Eigen::Ref<const QuaternionArray>& q_a,
                  const Eigen::Ref<const PositionArray>& r_b,
                  const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Index begin,
                  Eigen::Index end, const Eigen::Ref<Eigen::VectorXd>& value,
                  const Eigen::Ref<GradientArray>& gradient, std::uint8_t* left) {
  HWY_DYNAMIC_DISPATCH(CapsuleRows)(pair, r_a, q_a, r_b, q_b, begin, end, value, gradient, left);
}

}  // namespace diffpills::detail
#endif  // HWY_ONCE
