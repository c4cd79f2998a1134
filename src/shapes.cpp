#include "diffpills/shapes.hpp"

#include <string>

#include "validation.hpp"

namespace diffpills {

Capsule::Capsule(double length, double radius) : length_(length), radius_(radius) {
  detail::require_nonnegative(length, [] { return "capsule.length"; });
  detail::require_nonnegative(radius, [] { return "capsule.radius"; });
}

Pose::Pose() : r_(Eigen::Vector3d::Zero()), q_(1.0, 0.0, 0.0, 0.0) {}

Pose::Pose(const Eigen::Vector3d& r, const Eigen::Vector4d& q) : r_(r), q_(q) {
  for (int i = 0; i < 3; ++i) {
    detail::require_finite(r(i), [i] { return "pose.r[" + std::to_string(i) + "]"; });
  }
  for (int i = 0; i < 4; ++i) {
    detail::require_finite(q(i), [i] { return "pose.q[" + std::to_string(i) + "]"; });
  }
  // Derivatives with respect to q carry 1 / |q| (second derivatives 1 / |q|^2), because q is
  // normalized where it is used. In the largest accepted scene (positions up to 1e100 in each
  // coordinate, cores within 1e100 of their origins) a gradient's quaternion part can reach
  // ~1e202 / |q|: a norm of at least 1e-40 keeps first and second derivatives finite (below
  // ~1e282). fuzz_proximity found an infinite gradient at |q| = 2e-146.
  constexpr double kMinQuaternionNorm = 1e-40;
  if (!(q.norm() >= kMinQuaternionNorm)) {
    detail::fail("pose.q", "quaternion must be nonzero (its norm is below 1e-40)");
  }
}

}  // namespace diffpills
