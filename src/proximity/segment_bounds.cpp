// Compiled once per instruction set by Highway's foreach_target (this file includes itself through
// HWY_TARGET_INCLUDE); the code outside HWY_NAMESPACE is compiled once (HWY_ONCE).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "proximity/segment_bounds.cpp"
#include "segment_bounds.hpp"

// The columns are padded for vectors of at most 8 doubles: not compiled for Highway's scalable
// targets, whose vectors may be longer.
#include <hwy/detect_targets.h>
#undef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <cstddef>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace diffpills::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Segment i of `first`, P(s) = m + s u, |s| <= h, against those of `second`, Q(t) = m' + t v,
// |t| <= k, a vector of them at a time: with w = m - m', c = u . w, f = v . w, cos = u . v,
// n = u x v,
//   s = clamp(-((w x v) . n) / |n|^2, -h, h),  t = clamp(f + s cos, -k, k),
//   and where t clamped, s = clamp(t cos - c, -h, h)
// (segment_segment.cpp's first regime, written as the fused capsule pass writes it),
// d^2 = |w + s u - t v|^2; near parallel the boxes' bound (max_k |w_k| - h - k)^2, 0 where that is
// negative (segment_bounds.hpp). Both are computed in every lane and one selected. Rows are
// independent, so their dependency chains (one division each) overlap.
double SegmentDistanceBounds(const SegmentColumns& first, const SegmentColumns& second,
                             double* HWY_RESTRICT lower) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const auto lanes = static_cast<Eigen::Index>(hn::Lanes(d));
  const Eigen::Index width = second.padded_size(), count = second.size();
  const V parallel = hn::Set(d, 1e-4), zero = hn::Zero(d);
  const V infinity = hn::Set(d, std::numeric_limits<double>::infinity());
  const auto clamp = [](V value, V low, V high) { return hn::Min(hn::Max(value, low), high); };
  V least = infinity;
  for (Eigen::Index i = 0; i < first.size(); ++i) {
    const auto broadcast = [&](int row) { return hn::Set(d, first.row(row)[i]); };
    const V mx = broadcast(0), my = broadcast(1), mz = broadcast(2);
    const V ux = broadcast(3), uy = broadcast(4), uz = broadcast(5);
    const V h = broadcast(6), minus_h = hn::Neg(h);
    for (Eigen::Index j = 0; j < width; j += lanes) {
      const V wx = mx - hn::LoadU(d, second.row(0) + j), wy = my - hn::LoadU(d, second.row(1) + j),
              wz = mz - hn::LoadU(d, second.row(2) + j);
      const V vx = hn::LoadU(d, second.row(3) + j), vy = hn::LoadU(d, second.row(4) + j),
              vz = hn::LoadU(d, second.row(5) + j);
      const V k = hn::LoadU(d, second.row(6) + j);
      const V c = hn::MulAdd(ux, wx, hn::MulAdd(uy, wy, uz * wz));
      const V f = hn::MulAdd(vx, wx, hn::MulAdd(vy, wy, vz * wz));
      const V cos = hn::MulAdd(ux, vx, hn::MulAdd(uy, vy, uz * vz));
      const V nx = hn::MulSub(uy, vz, uz * vy), ny = hn::MulSub(uz, vx, ux * vz),
              nz = hn::MulSub(ux, vy, uy * vx);
      const V sin2 = hn::MulAdd(nx, nx, hn::MulAdd(ny, ny, nz * nz));
      const V across =
          hn::MulAdd(hn::MulSub(wy, vz, wz * vy), nx,
                     hn::MulAdd(hn::MulSub(wz, vx, wx * vz), ny, hn::MulSub(wx, vy, wy * vx) * nz));
      const V s_free = clamp(hn::Neg(across) / sin2, minus_h, h);
      const V t_free = hn::MulAdd(s_free, cos, f);
      const V t = clamp(t_free, hn::Neg(k), k);
      const V s =
          hn::IfThenElse(hn::Eq(t, t_free), s_free, clamp(hn::MulSub(t, cos, c), minus_h, h));
      const V Dx = hn::NegMulAdd(t, vx, hn::MulAdd(s, ux, wx)),
              Dy = hn::NegMulAdd(t, vy, hn::MulAdd(s, uy, wy)),
              Dz = hn::NegMulAdd(t, vz, hn::MulAdd(s, uz, wz));
      const V distance2 = hn::MulAdd(Dx, Dx, hn::MulAdd(Dy, Dy, Dz * Dz));
      const V box = hn::Max(hn::Max(hn::Abs(wx), hn::Abs(wy)), hn::Abs(wz)) - h - k;
      const V box2 = hn::IfThenElseZero(hn::Gt(box, zero), box * box);
      hn::StoreU(hn::IfThenElse(hn::Gt(sin2, parallel), distance2, box2), d, lower + i * width + j);
      // The padding's lanes (zero-length segments at the origin, whose clamps still give a
      // point) are left out by count, and NaN (0 / 0 where Max and Min pass it on) fails Eq
      // with itself.
      const auto counted =
          hn::And(hn::FirstN(d, static_cast<std::size_t>(j < count ? count - j : 0)),
                  hn::Eq(distance2, distance2));
      least = hn::Min(least, hn::IfThenElse(counted, distance2, infinity));
    }
  }
  return hn::GetLane(hn::MinOfLanes(d, least));
}

const char* SegmentBoundsTarget() { return hwy::TargetName(HWY_TARGET); }

bool SegmentBoundsVectorized() { return hn::Lanes(hn::ScalableTag<double>()) >= 4; }

}  // namespace HWY_NAMESPACE
}  // namespace diffpills::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace diffpills::detail {

HWY_EXPORT(SegmentDistanceBounds);
HWY_EXPORT(SegmentBoundsTarget);
HWY_EXPORT(SegmentBoundsVectorized);

double segment_distance_bounds(const SegmentColumns& first, const SegmentColumns& second,
                               double* lower) {
  return HWY_DYNAMIC_DISPATCH(SegmentDistanceBounds)(first, second, lower);
}

bool segment_bounds_vectorized() { return HWY_DYNAMIC_DISPATCH(SegmentBoundsVectorized)(); }

const char* segment_bounds_target() { return HWY_DYNAMIC_DISPATCH(SegmentBoundsTarget)(); }

}  // namespace diffpills::detail
#endif  // HWY_ONCE
