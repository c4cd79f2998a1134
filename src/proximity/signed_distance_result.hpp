// From a solved pair to the public signed-distance results (signed_distance.hpp): distance,
// points, normal, gradient (envelope theorem) and, on request, the Jacobians of the points
// (implicit function theorem, point_motion.hpp) with the normal's motion. Computed in the query's
// frame (pair_frame.hpp) and brought back to the inputs' units by powers of its scale: distance,
// points and the gradient's quaternion part by s, the Jacobians' quaternion columns by s.
#pragma once

#include <array>

#include "contact_normal.hpp"
#include "diffpills/signed_distance.hpp"
#include "pair_frame.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

// The pair's answer in the frame: the two sides, s (|x2 - x1| apart, minus the depth in
// penetration) and the unit normal with its source.
struct SignedSolution {
  std::array<ClosestFeature, 2> sides;
  double gap = 0.0;
  bool penetrating = false;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  NormalSource source;
};

SignedDistance make_signed_distance(const PairFrame& frame, const Pose& pose_a, const PosedCore& a,
                                    const Pose& pose_b, const PosedCore& b,
                                    const SignedSolution& solution);
// With normal_jacobian, also d normal / d[r1 q1 r2 q2] in the inputs' units.
SignedDistanceJacobian make_signed_distance_jacobian(
    const PairFrame& frame, const Pose& pose_a, const PosedCore& a, const Pose& pose_b,
    const PosedCore& b, const SignedSolution& solution,
    Eigen::Matrix<double, 3, 14>* normal_jacobian = nullptr);

}  // namespace diffpills::detail
