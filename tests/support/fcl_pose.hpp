// Our pose as FCL's transform of a capsule, for the tests that compare with FCL.
#pragma once

#include <fcl/common/types.h>

#include <Eigen/Geometry>
#include <cmath>

#include "diffpills/shapes.hpp"

namespace diffpills::testing {

// FCL's capsule axis is its body z; ours is body x. R_y(+90 deg) maps z to x.
inline fcl::Transform3d fcl_capsule_transform(const Pose& pose) {
  const Eigen::Quaterniond q(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
  fcl::Transform3d transform = fcl::Transform3d::Identity();
  transform.linear() = q.normalized().toRotationMatrix() *
                       Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  transform.translation() = pose.r();
  return transform;
}

}  // namespace diffpills::testing
