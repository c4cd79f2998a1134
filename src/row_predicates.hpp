// The two predicates of a polygon's reduction (padded_polygon.cpp), on its rows as given, with
// their signs exact: whether two rows' normals turn counterclockwise (k = p x q), and how far a
// third row cuts the vertex of two others (E below). Rounded unit normals decide both by noise
// when rows are nearly parallel or nearly opposite (a hostile review: a needle stretched to the
// wrong side, a nearly parallel row kept with vertices 1,000 times the polygon's size away).
//
// Each value is first computed in floating point with a bound on its rounding error (Shewchuk's
// filter); only when the value is within that bound of 0 is it summed again exactly: every
// product split into its rounded value and its error by a fused multiply-add (exact unless a
// product underflows, below 1e-300 of the rows' scale), the terms added into a nonoverlapping
// expansion (Shewchuk's grow-expansion), whose largest component has the sum's sign.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <utility>

namespace diffpills::detail {

// A sum of doubles held exactly as components of increasing magnitude that do not overlap.
class Expansion {
 public:
  // Adds x exactly (Knuth's two-sum at each component; zero components are dropped).
  void add(double x) {
    int kept = 0;
    for (int i = 0; i < size_; ++i) {
      const double sum = x + parts_[static_cast<std::size_t>(i)];
      const double virtual_part = sum - x;
      const double error =
          (x - (sum - virtual_part)) + (parts_[static_cast<std::size_t>(i)] - virtual_part);
      x = sum;
      if (error != 0.0) parts_[static_cast<std::size_t>(kept++)] = error;
    }
    size_ = kept;
    if (x != 0.0) parts_[static_cast<std::size_t>(size_++)] = x;
  }
  // Adds a b exactly: its rounded value and the rounding error.
  void add_product(double a, double b) {
    const double product = a * b;
    add(std::fma(a, b, -product));
    add(product);
  }
  int sign() const {
    if (size_ == 0) return 0;
    return parts_[static_cast<std::size_t>(size_ - 1)] > 0.0 ? 1 : -1;
  }
  // The sum, to within one rounding.
  double value() const {
    double out = 0.0;
    for (int i = 0; i < size_; ++i) out += parts_[static_cast<std::size_t>(i)];
    return out;
  }

 private:
  std::array<double, 64> parts_{};
  int size_ = 0;
};

// A value and the sign it has exactly.
struct SignedValue {
  double value;
  int sign;
};

// p x q = p_x q_y - p_y q_x.
inline SignedValue turn(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const double a = p.x() * q.y(), b = p.y() * q.x();
  const double value = a - b;
  // |error| <= 3 eps (|a| + |b|) for the two products and the difference (eps = 2^-53).
  if (std::abs(value) > 4 * DBL_EPSILON * (std::abs(a) + std::abs(b))) {
    return {value, value > 0.0 ? 1 : -1};
  }
  Expansion exact;
  exact.add_product(p.x(), q.y());
  exact.add_product(-p.y(), q.x());
  return {exact.value(), exact.sign()};
}

// For rows p . y <= s, q . y <= t, r . y <= u (offsets > 0) with p x r > 0: the vertex v of the
// first and last lies beyond the middle row by q . v - t = E / (p x r), with
//   E = s (q x r) + u (p x q) - t (p x r);
// E's sign exactly, and its value divided by a power of two (the offsets' scale).
inline SignedValue cut(const Eigen::Vector2d& p, double s, const Eigen::Vector2d& q, double t,
                       const Eigen::Vector2d& r, double u) {
  // The offsets scaled by a power of two (exactly) so that the largest is about 1: offsets of
  // 1e-297 times the cross products' error parts would underflow and lose the exactness.
  int exponent = 0;
  std::frexp(std::max({s, t, u}), &exponent);
  s = std::ldexp(s, -exponent), t = std::ldexp(t, -exponent), u = std::ldexp(u, -exponent);
  const double qr = q.x() * r.y() - q.y() * r.x();
  const double pq = p.x() * q.y() - p.y() * q.x();
  const double pr = p.x() * r.y() - p.y() * r.x();
  const double value = s * qr + u * pq - t * pr;
  const auto size = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return std::abs(a.x() * b.y()) + std::abs(a.y() * b.x());
  };
  // Each cross product is within 3 eps of its terms' size, each scaled and summed term adds 2
  // eps more: 8 eps of the terms' size bounds the error, with room.
  const double bound = 8 * DBL_EPSILON * (s * size(q, r) + u * size(p, q) + t * size(p, r));
  if (std::abs(value) > bound) return {value, value > 0.0 ? 1 : -1};
  Expansion exact;
  const auto add_scaled_cross = [&](double scale, const Eigen::Vector2d& a,
                                    const Eigen::Vector2d& b) {
    // scale (a_x b_y - a_y b_x), each product split exactly, then each part times the scale.
    for (const auto& [x, y] : {std::pair{a.x(), b.y()}, std::pair{-a.y(), b.x()}}) {
      const double product = x * y;
      const double error = std::fma(x, y, -product);
      exact.add_product(scale, product);
      exact.add_product(scale, error);
    }
  };
  add_scaled_cross(s, q, r);
  add_scaled_cross(u, p, q);
  add_scaled_cross(-t, p, r);
  return {exact.value(), exact.sign()};
}

}  // namespace diffpills::detail
