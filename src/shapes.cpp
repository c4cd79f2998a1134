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
  // Below ~1e-154 the squared norm underflows to zero and normalization would divide by zero.
  constexpr double kMinQuaternionNorm = 1e-150;
  if (!(q.norm() >= kMinQuaternionNorm)) {
    detail::fail("pose.q", "quaternion must be nonzero (its norm is below 1e-150)");
  }
}

}  // namespace diffpills
