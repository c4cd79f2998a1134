// proximity() and proximity_jacobian() of two capsules in one pass (issue 13): the generic case
// without the general pipeline's pair frame object, posed cores, rotation matrices, feature-based
// normal and general implicit-function-theorem solve.
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

#include "diffpills/proximity.hpp"
#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// True and `result` filled in the generic case above; false (result unspecified) otherwise.
bool generic_capsule_proximity(const Capsule& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b, Proximity& result);

// The same, with the closest points' Jacobians: in the generic case the implicit function
// theorem's system has at most two free coordinates (s and t along the axes), solved in closed
// form. The Proximity part is generic_capsule_proximity's, bit for bit.
bool generic_capsule_proximity_jacobian(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                        const Pose& pose_b, ProximityJacobian& result);

}  // namespace diffpills::detail
