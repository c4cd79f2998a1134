#include "pair_frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diffpills::detail {

// scale = 2^e with e = floor(log2 size), so that size / scale is in [1, 2). e is kept >= -1000:
// below that (a scene of subnormal numbers) 1 / scale would overflow; such a scene is then solved
// at a size down to 2^-74, still far from underflow in the squares the solvers form.
// The distance of the origins is taken as m |offset / m| with m the largest component, so that
// it neither underflows (offsets of 1e-200) nor overflows.
PairFrame make_pair_frame(double size_a, double radius_a, double size_b, double radius_b,
                          const Eigen::Vector3d& r_a, const Eigen::Vector3d& r_b) {
  const Eigen::Vector3d offset = r_b - r_a;
  const double largest = offset.lpNorm<Eigen::Infinity>();
  const double distance = largest > 0.0 ? largest * (offset / largest).norm() : 0.0;
  const double size = std::max({size_a, size_b, radius_a, radius_b, distance});
  PairFrame frame;
  if (size > 0.0) {
    const int size_exponent = std::ilogb(size);
    const int exponent = std::max(size_exponent, -1000);
    frame.scale = std::ldexp(1.0, exponent);
    frame.inverse_scale = std::ldexp(1.0, -exponent);
    frame.unit = std::ldexp(1.0, size_exponent - exponent);
  }
  // The sizes are brought into the frame before the factors are applied: the other order
  // underflows for a subnormal scene (1e-12 of 1e-317), where the frame's sizes are normal. Both
  // orders give the same bits otherwise (a power of two commutes with rounding).
  const double frame_size = size * frame.inverse_scale;
  frame.tolerance = 1e-12 * frame_size;
  frame.tie_tolerance = 2e-12 * (std::max(size_a, size_b) * frame.inverse_scale) +
                        64 * std::numeric_limits<double>::epsilon() * frame_size;
  return frame;
}

CoreTolerances core_tolerances(const PairFrame& frame, double size_a, double size_b,
                               double distance) {
  const double cores = std::max({size_a, size_b, distance});
  if (cores < 1e-100) return {frame.tolerance, frame.tie_tolerance};
  return {std::min(frame.tolerance, 1e-12 * cores),
          std::min(frame.tie_tolerance, 2e-12 * std::max(size_a, size_b) +
                                            64 * std::numeric_limits<double>::epsilon() * cores)};
}

}  // namespace diffpills::detail
