#include "segment_segment.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>

namespace diffpills::detail {

// In length units, from the middles: P(s) = m + s u, Q(t) = n + t v with unit u, v,
// s in [-h, h], t in [-k, k] (h, k the half lengths), and w = m - n. The squared distance is
// |w + s u - t v|^2; with cos = u.v, c = u.w, f = v.w the best t for a given s is f + s cos and
// the best s for a given t is t cos - c. Working from the middles keeps w, c and f of the size of
// the segments' distance near their middles rather than of their half lengths.
//
// The stationary point (eq. capsule_opt without bounds). With n = u x v, |n| = sin of the angle,
// crossing w + s u - t v = lambda n with v and dotting with n gives
//   s* = -((w x v) . n) / |n|^2,   and t* = f + s* cos, the best partner of s*.
// The order of the products matters. w x v is the part of w across v, small when the segments are
// nearly parallel (of order theta a + D, D the distance of the lines) but computed to eps |w|;
// dotting it with the small n adds eps (theta a + D). So s* errs by eps (|w| / theta + D /
// theta^2): eps / theta for lines that nearly meet, the conditioning of the problem itself, against
// eps / theta^2 from the Gram system (a s - b t = -c, b s - e t = -f solved by Cramer's rule, whose
// numerator b f - c e cancels to that level). Associating as w . (v x n) would lose the same way.
// t* is taken as the best partner of s* rather than from its own formula -((w x u) . n) / |n|^2:
// the two errors of order eps / theta would be independent, moving the points apart across the
// lines by that much, while a partner shifts with s* along the nearly common direction and the
// distance stays exact to eps.
//
// Three regimes by the angle:
//   - sin > 1e-3: Ericson's clamping (Real-Time Collision Detection 5.1.9): s* clamped, t the
//     best t for it; if t leaves [-k, k] it is clamped and s made the best s for it. Exact for
//     non-parallel segments, and s* is accurate to ~1e-13 relative here.
//   - 1e-12 < sin <= 1e-3: the distance varies slowly along the segments, and a clamp decided on
//     a slightly wrong side costs a distance error of order theta a. Appendix A's candidates are
//     compared by their distances instead: the stationary point if it lies in the box, and the
//     best point of each side of the box (a clamped projection).
//   - parallel, sin <= 1e-12: see the header. The threshold is on the sine, not its square: for
//     coplanar segments the distance changes linearly along the overlap, with slope ~ sin, so the
//     middle of the overlap is within ~1e-12 a of the optimum only at this threshold.
// Every quantity is of degree at most two in lengths (distances squared), so no length accepted
// by the library (up to 1e100) overflows or underflows.
SegmentParameters closest_segment_parameters(const Segment& P, const Segment& Q) {
  const double a = P.length, b = Q.length;
  const double h = 0.5 * a, k = 0.5 * b;
  const Eigen::Vector3d& u = P.direction;
  const Eigen::Vector3d& v = Q.direction;
  const Eigen::Vector3d w = P.middle - Q.middle;
  const double c = u.dot(w), f = v.dot(w), cos = u.dot(v);
  const auto best_t = [&](double s) { return std::clamp(f + s * cos, -k, k); };
  const auto best_s = [&](double t) { return std::clamp(t * cos - c, -h, h); };
  SegmentParameters out;
  double s = 0.0, t = 0.0;
  const Eigen::Vector3d n = u.cross(v);
  const double sin2 = n.squaredNorm();
  if (a == 0.0 || b == 0.0) {
    // A point (or two): the middle of a zero-length segment, the other's nearest point to it.
    t = b == 0.0 ? 0.0 : best_t(0.0);
    s = a == 0.0 ? 0.0 : best_s(t);
  } else if (sin2 > 1e-6) {
    s = std::clamp(-w.cross(v).dot(n) / sin2, -h, h);
    t = f + s * cos;
    if (t < -k || t > k) {
      t = std::clamp(t, -k, k);
      s = best_s(t);
    }
  } else if (sin2 > 1e-24) {
    const auto distance2 = [&](double s_, double t_) {
      return (w + s_ * u - t_ * v).squaredNorm();
    };
    const std::array<std::array<double, 2>, 4> sides = {
        {{-h, best_t(-h)}, {h, best_t(h)}, {best_s(-k), -k}, {best_s(k), k}}};
    double best = distance2(sides[0][0], sides[0][1]);
    s = sides[0][0], t = sides[0][1];
    for (const auto& [s_side, t_side] : sides) {
      const double d2 = distance2(s_side, t_side);
      if (d2 < best) best = d2, s = s_side, t = t_side;
    }
    const double s_star = -w.cross(v).dot(n) / sin2;
    const double t_star = f + s_star * cos;  // the best partner of s*, not t*'s own formula
    if (s_star >= -h && s_star <= h && t_star >= -k && t_star <= k &&
        distance2(s_star, t_star) < best) {
      s = s_star, t = t_star;
    }
  } else {
    // Parallel: the ends of Q project onto P's line at s0 (t = -k) and s1 (t = k). Where the
    // projections overlap [-h, h], every s of the overlap has a partner at the same distance and
    // the middle of the overlap is returned; otherwise the facing ends are unique.
    const double s0 = -k * cos - c, s1 = k * cos - c;
    const double low = std::max(-h, std::min(s0, s1));
    const double high = std::min(h, std::max(s0, s1));
    if (low <= high) {
      s = 0.5 * (low + high);
      t = best_t(s);
      out.overlap = low < high;
      out.half_overlap = 0.5 * (high - low) / a;
    } else {
      s = std::clamp(0.5 * (s0 + s1), -h, h);
      t = best_t(s);
      s = best_s(t);
    }
  }
  out.s_offset = s;
  out.t_offset = t;
  out.s = a > 0.0 ? s / a + 0.5 : 0.5;
  out.t = b > 0.0 ? t / b + 0.5 : 0.5;
  return out;
}

}  // namespace diffpills::detail
