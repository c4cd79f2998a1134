#include "broadphase.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace diffpills::detail {

std::vector<std::pair<int, int>> broadphase(const Scene& scene, const SceneOutlines& outlines,
                                            const std::vector<Pose>& body_poses, double margin,
                                            std::vector<UnitQuaternion>& attitudes) {
  attitudes.clear();
  if (body_poses.size() != scene.bodies().size()) {
    throw std::invalid_argument("body_poses: expected one pose per body, " +
                                std::to_string(scene.bodies().size()) + ", got " +
                                std::to_string(body_poses.size()));
  }
  if (!std::isfinite(margin) || std::abs(margin) > kMaxMagnitude) {
    throw std::invalid_argument("margin: must be finite, of magnitude at most 1e100");
  }
  const double grow = 0.5 * std::max(margin, 0.0);
  attitudes.reserve(body_poses.size());
  for (const Pose& pose : body_poses) attitudes.emplace_back(pose.q());
  std::vector<Box> boxes(outlines.primitives.size());
  for (std::size_t p = 0; p < boxes.size(); ++p) {
    const SceneOutlines::Primitive& primitive = outlines.primitives[p];
    const int body = primitive.body;
    const Eigen::Matrix3d& R = attitudes[static_cast<std::size_t>(body)].matrix();
    const Eigen::Vector3d& r = body_poses[static_cast<std::size_t>(body)].r();
    // The core's origin in the world (checked: the narrowphase takes it as a pose) ...
    const Eigen::Vector3d origin =
        r + R * scene.body(body).shapes()[static_cast<std::size_t>(primitive.shape)].pose.r();
    if (!(origin.cwiseAbs().maxCoeff() <= kMaxMagnitude)) {
      throw BodyPoseError(body, scene.body(body).name(), primitive.shape,
                          "its world position is beyond 1e100 in magnitude");
    }
    // ... and its points.
    Box& box = boxes[p];
    const Eigen::Vector3d* points = outlines.points.data() + primitive.first_point;
    box.low = box.high = r + R * points[0];
    for (int k = 1; k < primitive.point_count; ++k) {
      const Eigen::Vector3d v = r + R * points[k];
      box.low = box.low.cwiseMin(v);
      box.high = box.high.cwiseMax(v);
    }
    // Rounding of the corners (a few ulps of their magnitude): a relative margin far above it, so
    // that touching shapes keep overlapping boxes.
    const double slack =
        primitive.radius + grow +
        1e-12 * std::max(box.low.cwiseAbs().maxCoeff(), box.high.cwiseAbs().maxCoeff());
    box.low.array() -= slack;
    box.high.array() += slack;
  }
  std::vector<BoxFilter> filters(boxes.size());
  for (std::size_t p = 0; p < boxes.size(); ++p) {
    const int owner = outlines.primitives[p].body;
    const CollisionFilter& filter = scene.body(owner).filter();
    filters[p] = {owner, filter.category, filter.mask};
  }
  std::vector<std::pair<int, int>> pairs =
      overlapping_pairs(boxes, filters, [&scene](int i, int j) { return scene.checked(i, j); });
  for (auto& [u, v] : pairs) {
    if (outlines.primitives[static_cast<std::size_t>(u)].body >
        outlines.primitives[static_cast<std::size_t>(v)].body) {
      std::swap(u, v);
    }
  }
  return pairs;
}

}  // namespace diffpills::detail
