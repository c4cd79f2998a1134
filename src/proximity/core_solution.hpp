// One side of a solved pair, in fixed-size form: what every solver (closed form, feature
// enumeration, interior point) hands to the result builder.
//
// A core's closest point is p = r + Q u with u in the body frame. The active constraints at the
// solution leave the point free to move along some body-frame directions D (the columns of
// free_directions): none at a polygon vertex, a segment end or a sphere; the edge tangent on a
// polygon edge; the segment axis inside a segment; the body x-y plane inside a polygon face. Any
// basis of that subspace serves. The implicit function theorem then needs no constraint rows at
// all: near the solution the problem is min |p1(xi1) - p2(xi2)|^2 over the free coordinates xi.
#pragma once

#include <Eigen/Core>

#include "diffpills/shapes.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {

struct PosedCore {
  Eigen::Vector3d r;
  UnitQuaternion attitude;  // q normalized once, and Q(q); derivatives refer to q as given
  double radius = 0.0;
  double size = 0.0;  // the core's length scale, for relative tolerances
};

PosedCore posed_core(const Capsule& capsule, const Pose& pose);
PosedCore posed_core(const PaddedPolygon& polygon, const Pose& pose);

struct CoreSolution {
  Eigen::Vector3d body_point = Eigen::Vector3d::Zero();
  int free_dimensions = 0;  // 0, 1 or 2
  Eigen::Matrix<double, 3, 2> free_directions = Eigen::Matrix<double, 3, 2>::Zero();
};

}  // namespace diffpills::detail
