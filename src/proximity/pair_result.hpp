// From the two sides of a solved pair to the public results: phi, points, normal, gradient
// (envelope theorem) and, on request, the Jacobians of the points (implicit function theorem)
// and phi's Hessian (phi_hessian.hpp).
// Every solver ends here, so all of them report the same quantities the same way.
//
// Everything is computed in the query's frame (pair_frame.hpp) and then brought back to the
// units of the inputs by powers of the frame's scale s, exactly: phi and the gradient's quaternion
// part by s^2, the gradient's position part and the Jacobians' quaternion columns by s; points as
// r + s (Q u) from the inputs' own body origins r.
#pragma once

#include "diffpills/proximity.hpp"
#include "pair_frame.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

Proximity make_proximity(const PairFrame& frame, const Pose& pose_a, const PosedCore& a,
                         const ClosestFeature& side_a, const Pose& pose_b, const PosedCore& b,
                         const ClosestFeature& side_b);
ProximityJacobian make_proximity_jacobian(const PairFrame& frame, const Pose& pose_a,
                                          const PosedCore& a, const ClosestFeature& side_a,
                                          const Pose& pose_b, const PosedCore& b,
                                          const ClosestFeature& side_b);
ProximityHessian make_proximity_hessian(const PairFrame& frame, const Pose& pose_a,
                                        const PosedCore& a, const ClosestFeature& side_a,
                                        const Pose& pose_b, const PosedCore& b,
                                        const ClosestFeature& side_b);
ProximityWithHessian make_proximity_with_hessian(const PairFrame& frame, const Pose& pose_a,
                                                 const PosedCore& a, const ClosestFeature& side_a,
                                                 const Pose& pose_b, const PosedCore& b,
                                                 const ClosestFeature& side_b);

}  // namespace diffpills::detail
