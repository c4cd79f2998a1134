// Proximity queries between capsules and padded polygons (paper sections III-IV, DESIGN.md 1-4).
//
// Every query solves the closest-point problem between the two cores (a segment or a planar
// polygon each) as a small convex QP over the cores' parameters, then reports
//
//   phi = |p1 - p2|^2 - (R1 + R2)^2                                  (eq. caps_prox)
//
// with p1, p2 the closest core points: phi > 0 apart, phi <= 0 touching or overlapping. Every
// query is a pure function of its arguments: no global state, safe from any thread.
//
// Derivatives. gradient is d phi / d[r1, q1, r2, q2] (14 entries, shape 1 = the first argument).
// phi is the optimal value of a QP whose feasible set does not depend on the poses, so by the
// envelope (Danskin) theorem the gradient is that of |p1(x*) - p2(x*)|^2 with the core parameters
// x* held fixed; tests check it against the paper's OptNet route and finite differences.
// proximity_jacobian() adds the 6x14 Jacobians of [p1; p2] and of the surface points [p~1; p~2],
// from the implicit function theorem on the KKT conditions of the QP with its active set.
//
// Degenerate cases, chosen on purpose:
//   - Non-unique closest points (parallel segments, a segment parallel to a polygon's plane,
//     stacked parallel polygons, crossing cores): phi is exact and continuous; the closest points
//     are the middle of the optimal set, the midpoint of an interval or the area centroid of a
//     planar region (Method::kDefault). That choice moves continuously while the configuration
//     stays degenerate. The reference path (Method::kInteriorPoint) returns the interior-point
//     method's limit instead, the optimal point nearest its iterate, which tends to the analytic
//     centre of the optimal set: the same set, so phi and the gradient's position part agree, but
//     not always the same point in it. The closest points themselves jump when a configuration
//     leaves the degenerate set (two nearly parallel segments touch near one end of their
//     overlap, and which end flips with the sign of the angle); no choice avoids that. There the
//     Jacobians are the minimum-norm solution of the singular system.
//   - Parallelism thresholds are relative, so they mean the same at every scale: |sin| <= 1e-12
//     between a segment and a segment, a plane or another plane (where the distance varies
//     linearly with a tilt, so the middle of the optimal set stays within 1e-12 of optimal).
//     A polygon a few 1e-12 rad from parallel to another's face can have both edges at its
//     lowest vertex pass the test: the clearly flatter one (its slope at most half the other's)
//     gives the interval, and for slopes within a factor of two (a regular many-sided polygon
//     pointing its vertex down the slope) the vertex, the one closest point.
//     The optimal set is found from the candidates that tie: distances within 2e-12 of the larger
//     core's size plus 64 ulps of the scene's size, and the point candidate on the interval. (The
//     cores are searched without their radii: where the radii make the scene, its size here is
//     that of the cores' own, the larger core and the distance between the body origins.)
//     Shapes far apart compared to their size (a distance V, sizes h) have their closest points
//     to within the scene's rounding only: beyond V ~ 1e6 h neighbouring candidates' distances
//     differ by less than the tie tolerance. Among such ties a polygon's vertex over the other's
//     face, the vertex of its polygon nearest that face's plane, is kept: no pair is nearer. One
//     off the face by no more than 16 ulps of its coordinates' magnitude in the pair's frame
//     (their rounding cannot tell whether it is over the face) is kept in its pair with the
//     face's nearest boundary point, at that pair's true distance. Two polygons apart whose
//     heights over each other's planes vary by less than the rounding of their coordinates (here
//     64 ulps of V plus their sizes, and at most the tie tolerance: unit polygons 1e8 apart and up
//     to ~5e-7 rad from parallel) are level faces: every pair of features ties, and they are
//     solved as parallel faces across their mean normal, the centre of the overlap of their
//     shadows along it (or the middle of the shadows' closest set), each polygon's point over it,
//     the same in both orders. A polygon below ~1e-12 of its distance is a speck: its core point
//     may lie up to ~1e-12 of the distance off it, and the gradient's rotation part takes that
//     lever arm (two unit octagons 1e13 apart: dphi/dq 2.3e14 where central differences give
//     4e13), while phi and the distance keep their digits.
//   - Two polygons are solved with the same one in the role of the first in both orders of the
//     arguments (chosen by the polygons' own data, the one with more vertices first, and for
//     identical polygons by their relative poses), so that swapping them swaps the points and
//     permutes the gradient to rounding even where the tolerances decide the answer: a box's
//     edge resting on a table within the tolerance and tilted a few 1e-12 rad, whose planes
//     cross on a line that the edge's heights over the tilt place anywhere along it. A rigid
//     motion and the sign of a quaternion keep the roles; a rigid motion moves such a crossing
//     by the rounding of the heights over the tilt (~1e-16 of the size / tilt), the problem's
//     own conditioning. (Two identical polygons whose relative pose is its own inverse, a half
//     turn, prefer no order: both roles pose the same problem, whose middle is the same point.)
//   - Each rule above decides at a threshold (the sine of 1e-12, the factor of two between
//     slopes, the tolerances at a face's boundary, the 16-ulp band of a vertex just off a face).
//     A configuration within the rounding of its own inputs of a threshold is decided by that
//     rounding, which a rigid motion of the scene or the order of the arguments changes: the
//     rotation made from a quaternion carries ~1e-16 of each length. There the points can move
//     within the features that tie (a polygon turned 2e-12 rad about an edge whose neighbour on a
//     6,000-edge arc climbs by 5e-16 gets that edge's middle or the vertex between them), while
//     phi keeps to the tie tolerance.
//   - Nearly parallel features that are not parallel by that test (a sine just above 1e-12)
//     have unique closest points and exact derivatives, computed from cross products of the
//     features' directions (src/proximity/point_motion.cpp), but the problem is ill-conditioned
//     there: the points' Jacobians, of size ~1 / sin, carry a relative error of ~eps / sin, and
//     the Hessian an absolute error of ~eps times the Jacobians' size squared (two segments
//     twisted by 1e-7: 0.03 on a Hessian of size 4; below a twist of ~1e-8 it is noise).
//     The points themselves are as sensitive: a change of the inputs by their rounding moves
//     them along the features by ~eps D / sin^2, D the features' gap (two unit segments 1 apart
//     and twisted by 1e-7 by 0.2: anywhere along the overlap below ~1e-8), and they are exact to
//     about that (~eps / sin where the gap is of the twist's order); phi and the distance keep
//     to ~1e-16 of the scene. python/tests/test_near_parallel.py checks both against 50 digits.
//   - Zero length capsules are spheres.
//   - Intersecting cores (|p1 - p2| <= 1e-12 of the scene's size): cores_intersect is true,
//     phi = -(R1 + R2)^2 and its gradient vanishes up to rounding (the proximity is flat there:
//     keep phi > 0 with a margin in optimizers). The normal is then undefined and replaced by a
//     deterministic choice: the unit vector from r1 to r2, or, if the origins coincide too, shape
//     1's body z axis Q(q1) [0, 0, 1]. Surface points and Jacobians follow that rule.
//   - Non-unit quaternions are normalized; derivatives include the normalization.
//   - Magnitudes. Every accepted input (lengths, radii, positions and offsets from 0 up to
//     kMaxMagnitude, polygons with offsets d_i / |C_i| as small as 1e-300) is answered to full
//     accuracy relative to the pair's scene: each pair is solved in a frame whose unit is a power
//     of two near the scene's size (the largest of the cores' sizes, the radii and the distance
//     between the body origins), and lengths come out with errors of about 1e-16 of that size
//     (polygons of more than 32 x 32 vertex pairs, solved in windows: a few 1e-12 of it). A
//     gap far smaller than the scene is resolved only to that absolute error (two specks 1e-300
//     apart beside a unit capsule get phi = 0), and below 1e-12 of it the cores touch. Segments
//     are solved from their middles, so a shape near the middle of a long capsule keeps its own
//     digits: a stick 1e9 beside the middle of a 1e20-long capsule gets phi = 1e18 to rounding.
//     Scaling every length by 2^k scales phi by exactly 2^(2k), the points by 2^k, the
//     gradient's position part by 2^k and its quaternion part by 2^(2k), bit for bit, while phi,
//     a squared length, stays a normal double: scenes down to ~1e-154. Below that phi loses
//     digits to subnormals and below ~1e-162 it underflows to 0 for shapes that are apart
//     (cores_intersect stays false; the points, the gradient and the signed distance, lengths,
//     stay exact down to ~1e-290). The normal is unit to rounding at every scale. One corner
//     is not answered to full accuracy: with |q| near its 1e100 bound and a closest point within
//     ~1e-250 of the scene from a capsule's middle, intermediate products pass below the double
//     range and quaternion derivatives that are normal numbers can come out 0 (in a 2^330
//     scene: the points' Jacobians and the Hessian, ~1e-251, and, off the fused capsule pass,
//     the gradient, ~3e-151).
//   - The normal (p2 - p1) / |p2 - p1| is taken from the closest features where they fix it: a
//     polygon's face normal when a point lies inside a face, e x f for two edges (or segments)
//     crossing. It then stays exact to a few ulps as the shapes approach touching, where the
//     direction of p2 - p1 itself is known only to ~1e-16 of the scene over |p2 - p1|
//     (src/proximity/contact_normal.hpp).
//
// Errors: shapes and poses validate on construction (std::invalid_argument). The default method
// never fails on valid shapes. The interior-point reference can: on badly scaled pairs (a core
// 1e-11 or less the size of the pair's separation, say, where its QP's data span 22 orders of
// magnitude) it may reach its iteration cap, and then throws SolverError rather than return an
// unverified answer.
#pragma once

#include <Eigen/Core>
#include <array>
#include <stdexcept>

#include "diffpills/shapes.hpp"

namespace diffpills {

enum class Method {
  // Exact fast paths: two segments in closed form (Appendix A's candidates), pairs with a polygon
  // by enumerating feature pairs in a polygon's body frame. No heap allocation for polygons of up
  // to 32 vertices. proximity(), proximity_jacobian(), proximity_hessian() and
  // proximity_with_hessian() of two capsules whose axes are more than ~5.7 degrees apart and
  // whose cores are apart by more than ~1e-2 of the scene take one fused pass
  // (src/proximity/capsule_proximity.hpp), whose fields the four share bit for bit and which
  // agrees with the general pipeline to rounding (~1e-13 relative). Its Hessian is formed in the
  // widest vectors the CPU runs (AVX-512, AVX2, SSE4 or plain code, chosen at run time), so its
  // last bits may differ between machines; it is exactly symmetric on all of them.
  kDefault,
  // The paper's interior-point method (section II-B) on the pair's QP, polished to its active
  // set: slower, kept as the reference the fast paths are tested against.
  kInteriorPoint,
};

struct ProximityOptions {
  Method method = Method::kDefault;
};

struct Proximity {
  double phi = 0.0;                            // |p1 - p2|^2 - (R1 + R2)^2
  std::array<Eigen::Vector3d, 2> core_points;  // p1 on core 1, p2 on core 2, world frame
  std::array<Eigen::Vector3d, 2> points;       // surface points p1 + R1 n, p2 - R2 n, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, world frame, from shape 1 to shape 2
  bool cores_intersect = false;  // p1 = p2: the normal is the documented fallback
  Eigen::Matrix<double, 14, 1> gradient =
      Eigen::Matrix<double, 14, 1>::Zero();  // dphi/d[r1 q1 r2 q2]
};

struct ProximityJacobian : Proximity {
  Eigen::Matrix<double, 6, 14> core_points_jacobian =
      Eigen::Matrix<double, 6, 14>::Zero();  // d[p1; p2]
  Eigen::Matrix<double, 6, 14> points_jacobian =
      Eigen::Matrix<double, 6, 14>::Zero();  // d[p~1; p~2]
};

// The 14 x 14 Hessian of phi with respect to [r1 q1 r2 q2] (quaternion normalization included),
// symmetric. Exact where phi is twice differentiable (unique closest points, strict
// complementarity); elsewhere the derivative of the reported gradient along the closest points'
// reported Jacobians (one of the one-sided choices); 0 where the cores intersect (phi is flat
// there). Derivation in src/proximity/phi_hessian.hpp.
struct ProximityHessian : ProximityJacobian {
  Eigen::Matrix<double, 14, 14> hessian = Eigen::Matrix<double, 14, 14>::Zero();
};

// phi, the points, the normal, the gradient and the same Hessian as ProximityHessian, without the
// points' Jacobians: what a Newton-type method (Ipopt with exact Hessians, SQP, interior-point MPC)
// asks of a collision constraint. Every field equals proximity_hessian()'s bit for bit; it only
// skips the two 6 x 14 Jacobians: two capsules in 2.4-3.3x the time of proximity() on a CPU with
// AVX2 or AVX-512 (3.0-4.1x with SSE4 alone or plain code) against proximity_hessian()'s 4-5x, a
// capsule and a hexagon 2.2x, two hexagons 1.6x (BENCHMARKS.md).
struct ProximityWithHessian : Proximity {
  Eigen::Matrix<double, 14, 14> hessian = Eigen::Matrix<double, 14, 14>::Zero();
};

// Thrown when the QP solver does not converge, or when the interior-point reference's point lies
// outside a polygon's spike sharper than its tolerance (src/proximity/proximity.cpp): never
// silently wrong.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Proximity proximity(const Capsule& a, const Pose& pose_a, const Capsule& b, const Pose& pose_b,
                    const ProximityOptions& options = {});
Proximity proximity(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                    const Pose& pose_b, const ProximityOptions& options = {});
Proximity proximity(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                    const Pose& pose_b, const ProximityOptions& options = {});
Proximity proximity(const PaddedPolygon& a, const Pose& pose_a, const PaddedPolygon& b,
                    const Pose& pose_b, const ProximityOptions& options = {});
Proximity proximity(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                    const ProximityOptions& options = {});

ProximityJacobian proximity_jacobian(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                     const Pose& pose_b, const ProximityOptions& options = {});
ProximityJacobian proximity_jacobian(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                                     const Pose& pose_b, const ProximityOptions& options = {});
ProximityJacobian proximity_jacobian(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                                     const Pose& pose_b, const ProximityOptions& options = {});
ProximityJacobian proximity_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                     const PaddedPolygon& b, const Pose& pose_b,
                                     const ProximityOptions& options = {});
ProximityJacobian proximity_jacobian(const Shape& a, const Pose& pose_a, const Shape& b,
                                     const Pose& pose_b, const ProximityOptions& options = {});

ProximityHessian proximity_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                   const Pose& pose_b, const ProximityOptions& options = {});
ProximityWithHessian proximity_with_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                            const Pose& pose_b,
                                            const ProximityOptions& options = {});

}  // namespace diffpills
