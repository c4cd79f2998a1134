#include "segment_segment.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>

namespace diffpills::detail {
namespace {

double clamp01(double value) { return std::clamp(value, 0.0, 1.0); }

}  // namespace

// With w = p - q the squared distance is |w + s u - t v|^2, and with
//   a = u.u,  b = u.v,  e = v.v,  c = u.w,  f = v.w
// its stationary point solves  a s - b t = -c,  b s - e t = -f,  determinant
// a e - b^2 = |u x v|^2 = a e sin^2 (taken from the cross product, free of cancellation).
// Three regimes by the angle between the segments:
//   - sin^2 > 1e-6 (Ericson, Real-Time Collision Detection 5.1.9): s from the stationary point,
//     clamped; t = (b s + f) / e, the best t for it; if t leaves [0, 1] it is clamped and s made
//     the best s for it. Exact, and the stationary point is accurate to 1e-10 relative.
//   - near parallel: the stationary point carries a relative error of eps / sin^2, enough to
//     clamp to the wrong end. The Appendix A candidates are compared instead, each distance
//     evaluated directly: the stationary point if it lies in the box, and the best point of each
//     side of the box (a clamped projection).
//   - parallel, |sin| <= 1e-12: see the header. The threshold is on the sine, not its square:
//     for coplanar segments the distance changes linearly along the overlap, with slope ~ sin, so
//     the middle of the overlap is within ~1e-12 |u| of the optimum only at this threshold.
SegmentParameters closest_segment_parameters(const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                             const Eigen::Vector3d& q, const Eigen::Vector3d& v) {
  const Eigen::Vector3d w = p - q;
  const double a = u.squaredNorm();
  const double e = v.squaredNorm();
  const double b = u.dot(v);
  const double c = u.dot(w);
  const double f = v.dot(w);
  SegmentParameters out;
  if (a == 0.0 && e == 0.0) return out;
  if (a == 0.0) {
    out.t = clamp01((f + 0.5 * b) / e);  // the best t for the point p + u / 2 = p
    return out;
  }
  if (e == 0.0) {
    out.s = clamp01((0.5 * b - c) / a);
    return out;
  }
  const double det = u.cross(v).squaredNorm();
  if (det > 1e-6 * a * e) {
    out.s = clamp01((b * f - c * e) / det);
    out.t = (b * out.s + f) / e;
    if (out.t < 0.0) {
      out.t = 0.0;
      out.s = clamp01(-c / a);
    } else if (out.t > 1.0) {
      out.t = 1.0;
      out.s = clamp01((b - c) / a);
    }
    return out;
  }
  if (det > 1e-24 * a * e) {
    const auto distance2 = [&](const SegmentParameters& x) {
      return (w + x.s * u - x.t * v).squaredNorm();
    };
    const std::array<SegmentParameters, 4> sides = {
        SegmentParameters{0.0, clamp01(f / e)}, SegmentParameters{1.0, clamp01((b + f) / e)},
        SegmentParameters{clamp01(-c / a), 0.0}, SegmentParameters{clamp01((b - c) / a), 1.0}};
    out = sides[0];
    for (const SegmentParameters& side : sides) {
      if (distance2(side) < distance2(out)) out = side;
    }
    const double s = (b * f - c * e) / det;
    const double t = (b * s + f) / e;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0 && distance2({s, t}) < distance2(out)) {
      out = {s, t};
    }
    return out;
  }
  // Parallel: the ends of Q project onto P's line at s0 (t = 0) and s1 (t = 1). Where the
  // projections overlap [0, 1], every s of the overlap has a partner at the same distance and the
  // middle of the overlap is returned; otherwise the facing ends are unique.
  const double s0 = -c / a;
  const double s1 = (b - c) / a;
  const double low = std::max(0.0, std::min(s0, s1));
  const double high = std::min(1.0, std::max(s0, s1));
  out.s = low <= high ? 0.5 * (low + high) : clamp01(0.5 * (s0 + s1));
  out.t = clamp01((b * out.s + f) / e);
  if (low > high) {
    out.s = clamp01((b * out.t - c) / a);
  }
  return out;
}

}  // namespace diffpills::detail
