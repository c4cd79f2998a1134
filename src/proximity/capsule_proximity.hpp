// proximity(), proximity_jacobian(), proximity_hessian() and proximity_with_hessian() of two
// capsules in one pass (issues 12 and 13): the generic case without the general pipeline's pair
// frame object, posed cores, rotation matrices, feature-based normal and general
// implicit-function-theorem solve.
//
// The general pipeline (proximity.cpp) builds both cores' 3 x 3 rotations and quaternion
// Jacobians, hands the closest points to the shared result builder as body points with free
// directions, and picks the normal from the features. For two capsules most of that is unused:
// only each body's x axis is needed, the gradient follows from the envelope theorem, and where
// the cores are well apart the normal is the closest points' direction. This path computes just
// that, and answers only what it answers as exactly as the general pipeline:
//   - both lengths nonzero (a zero-length capsule is a sphere: the general pipeline's);
//   - the scene's size S (largest of the lengths, the radii and the largest component of the
//     offset between the middles) at least 2^-1000, so that 1 / 2^e stays a normal number, 2^e
//     the power of two with 2^e <= S < 2^(e + 1); each length at least 2^-500 2^e (a shorter
//     core is a point to rounding);
//   - the axes more than ~5.7 degrees from parallel (sin^2 > 1e-2): nearer parallel the closest
//     points are sensitive to the axes' rounding (~eps / sin^2), and the general pipeline's
//     near-parallel regimes compare candidates instead;
//   - no clamp decided within 2^-36 2^e of its bound (an end of a core; the whole of a core
//     shorter than 2^-35 2^e whose closest point is inside it): the two paths' rounding may take
//     different sides of such a tie, where the points' Jacobians and phi's Hessian are one-sided;
//   - the cores apart by more than 1e-2 2^e (nearer, the general pipeline takes the normal from
//     the features there, and decides intersection). The normal follows contact_normal.hpp's rule
//     as the general pipeline does: -+(u x v) / |u x v| for two points inside their segments
//     where sin >= |D|, else D / |D|, exact to a few eps S / |D| (~1e-14) once an end is held.
//     (|D| in this frame, whose power of two comes from the largest offset component rather than
//     the offset's length, so near sin = |D| the two paths may pick differently between two
//     normals that agree to ~1e-15.)
// Everything else (about 0.5% of random poses) returns false and the caller takes the general
// pipeline. Lengths are divided by 2^e, so a scene scaled by 2^k gives the
// same bits scaled as the general pipeline's results do (pair_frame.hpp), and the case test is
// scale invariant.
#pragma once

#include <Eigen/Core>

#include "diffpills/proximity.hpp"
#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// A quaternion q as the fused pass uses it: q^ = q / |q|, 1 / |q| and the body x axis Q(q^) e_x.
struct AxisAttitude {
  Eigen::Vector4d unit;
  double inverse_norm;
  Eigen::Vector3d axis;
};

// The generic case solved in the frame (capsule_proximity.cpp's solve_generic), what every
// result is built from.
struct GenericCapsuleSolution {
  AxisAttitude attitude_a, attitude_b;
  double scale;         // the frame's power of two
  double s, t;          // the closest points' offsets from the middles along u and v, in the frame
  Eigen::Vector3d n;    // u x v
  double sin2;          // |u x v|^2
  double cos;           // u . v
  bool s_free, t_free;  // s, t strictly inside their segments
  bool edge_normal;     // the normal is the edges' -+(u x v) / |u x v| (generic_proximity)
  Eigen::Vector3d D;    // p1 - p2 in the frame
  double D2;            // |D|^2
};

// The fused pass's Proximity in the generic case above, general(a, pose_a, b, pose_b) otherwise;
// returned by value and built in place either way. (Filled through a reference, the result was
// default-constructed first, its gradient zeroed by a rep stos: 55.1 / 53.6 -> 53.1 / 52.6 ns in
// a paired run, BENCHMARKS.md.)
using GeneralCapsuleProximity = Proximity (*)(const Capsule&, const Pose&, const Capsule&,
                                              const Pose&);
Proximity generic_capsule_proximity(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                    const Pose& pose_b, GeneralCapsuleProximity general);

// True and `solution` filled in the generic case; false otherwise.
bool solve_generic_capsules(const Capsule& a, const Pose& pose_a, const Capsule& b,
                            const Pose& pose_b, GenericCapsuleSolution& solution);

// The results of a generic case's solution, with the closest points' Jacobians (the implicit
// function theorem's system has at most two free coordinates, s and t along the axes, solved in
// closed form) and with phi's Hessian (the second-order theorem over the same coordinates, a Gram
// matrix of at most five rows: symmetric_gram.hpp), or with the Hessian alone. All repeat
// generic_capsule_proximity's Proximity part bit for bit, the Hessian the Jacobian's part, and
// the Hessian alone the Hessian. Returned by value, built in place: each large matrix is a
// prvalue of the aggregate's initializer, so the default member initializers never zero them
// first (~30 ns for the Jacobians, ~45 ns with the Hessian, measured).
ProximityJacobian generic_capsule_proximity_jacobian(const GenericCapsuleSolution& solution,
                                                     const Capsule& a, const Pose& pose_a,
                                                     const Capsule& b, const Pose& pose_b);
ProximityHessian generic_capsule_proximity_hessian(const GenericCapsuleSolution& solution,
                                                   const Capsule& a, const Pose& pose_a,
                                                   const Capsule& b, const Pose& pose_b);
ProximityWithHessian generic_capsule_proximity_with_hessian(const GenericCapsuleSolution& solution,
                                                            const Capsule& a, const Pose& pose_a,
                                                            const Capsule& b, const Pose& pose_b);

// Every field by the general pipeline, whatever the case: what the fused pass is checked against
// (tests, fuzz_proximity). Defined in proximity.cpp.
ProximityHessian general_capsule_proximity_hessian(const Capsule& a, const Pose& pose_a,
                                                   const Capsule& b, const Pose& pose_b);

}  // namespace diffpills::detail
