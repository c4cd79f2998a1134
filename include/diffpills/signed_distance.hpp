// The signed distance between capsules and padded polygons, with exact derivatives also in
// penetration (DESIGN.md section 2b).
//
// The paper's proximity phi = |p1 - p2|^2 - (R1 + R2)^2 is flat once the cores intersect: phi is
// -(R1 + R2)^2 and its gradient vanishes, so an optimizer started from overlapping shapes sees no
// way out. The signed distance keeps a slope everywhere:
//
//   distance = s - R1 - R2,   s = dist(0, D) when 0 is outside D = K1 - K2 (the cores apart),
//                             s = -dist(0, boundary of D) when inside (their penetration depth),
//
// with K1, K2 the cores (segments, polygons) and D their Minkowski difference. So distance > 0 is
// the gap between the padded surfaces and distance < 0 minus the padded shapes' translational
// penetration depth: translating shape 2 by -distance * normal makes the shapes touch. It is
// continuous, also across touching, and equals |p1 - p2| - R1 - R2 of proximity()'s closest
// points whenever the cores are apart.
//
// Points, normal. normal is unit, from shape 1 to shape 2: (p2 - p1) / |p2 - p1| apart, the
// outward normal of D's nearest facet in penetration; from the features (a face's normal, e x f
// of two edges) wherever they fix it, so that it is exact also near touching (proximity.hpp).
// core_points = {x1, x2} on the cores with x2 - x1 = s * normal (apart: the closest points; in
// penetration: the deepest points of the two cores along the normal), points = {x1 + R1 normal, x2
// - R2 normal} on the surfaces, so that points[1] - points[0] = distance * normal. Where those
// points are not unique, the middle of the set, as for proximity().
//
// Derivatives. Apart, s is the optimal value of the closest-point problem; in penetration, of
// min over unit n of h_1(n) + h_2(-n) (support functions), whose feasible set does not depend on
// the poses either. By the envelope theorem both give
//
//   d distance = normal . (dp2 - dp1)   with the points' body coordinates held fixed,
//
// one formula on both sides of touching. signed_distance_jacobian() adds the 6x14 Jacobians of
// the core and surface points (implicit function theorem on the features that hold them: the
// closest features, or the face and vertex, or the two edges, of the nearest facet) with the
// normal's own motion.
//
// Degenerate cases, chosen on purpose:
//   - D flat (two segments, a segment lying in a polygon's plane, coplanar polygons) and holding
//     0: s = 0, distance = -(R1 + R2). Its two normals +-n (n normal to D's plane) tie, and the
//     one pointing from shape 1's body origin to shape 2's is taken (n . (r2 - r1) > 0), or if
//     they are level, the one along shape 1's body z axis. Two polygons are solved with the same
//     one as shape 1 in both orders of the arguments (as by proximity(), proximity.hpp), so that
//     swapping them reverses the normal; not two identical polygons a half turn apart, whose
//     orders a rigid motion exchanges, so that no choice is preferred. For parallel segments (or
//     spheres) whose D is a segment or a point, the normal is the part of r2 - r1 normal to the
//     segments, or if that vanishes shape 1's (or else shape 2's) body z axis made normal to
//     them; its derivative is taken as zero there.
//   - Penetrating facets that tie (a capsule through a polygon's centre, equally deep both ways)
//     are decided by the same rule; the normal then jumps as the configuration leaves the tie,
//     and the gradient is that of the chosen facet (one-sided).
//   - Cores crossing nearly coplanar: D is thin, and facets within the tolerance of the nearest
//     one in depth can lie far apart along it. Only a facet whose nearest point lies on it is
//     taken, so the witnesses always lie on the two cores (penetration.hpp).
//   - Tolerances are relative, as for proximity(): 1e-12 of the scene's size, or of the cores'
//     own (the larger core and the distance between the body origins) where the radii make the
//     scene, since the radii play no part in the cores' gap and depth (cores 1e-140 to 1e-100 of
//     the radii are solved in a frame of their own size; smaller ones keep the scene's tolerances
//     and touch at any gap: s = 0 and a normal held fixed, answered without a search); and every
//     input proximity() accepts is answered at every magnitude; scaling all lengths by 2^k scales
//     distance and the points by 2^k, the gradient's quaternion part by 2^k, exactly.
//
// Cost: that of proximity() apart; in penetration O(m) for a capsule and an m-gon. Two polygons
// have m1 m2 edge-pair facets; up to 32 x 32 vertices each pair is visited (nothing is allocated),
// above, a search of bounding hierarchies over the two polygons' edge chains visits only the pairs
// that can hold the nearest facet, about O((m1 + m2) log): two crossing 10^5-gons take ~15 ms.
#pragma once

#include <Eigen/Core>
#include <array>

#include "diffpills/shapes.hpp"

namespace diffpills {

struct SignedDistance {
  double distance = 0.0;                              // s - R1 - R2
  std::array<Eigen::Vector3d, 2> points;              // on the two surfaces, world frame
  std::array<Eigen::Vector3d, 2> core_points;         // on the two cores, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, from shape 1 to shape 2
  bool penetrating = false;  // the cores intersect (s <= 0 up to the tolerance)
  Eigen::Matrix<double, 14, 1> gradient =
      Eigen::Matrix<double, 14, 1>::Zero();  // d distance / d[r1 q1 r2 q2]
};

struct SignedDistanceJacobian : SignedDistance {
  Eigen::Matrix<double, 6, 14> core_points_jacobian =
      Eigen::Matrix<double, 6, 14>::Zero();  // d[x1; x2]
  Eigen::Matrix<double, 6, 14> points_jacobian =
      Eigen::Matrix<double, 6, 14>::Zero();  // d[points[0]; points[1]]
};

// The 14 x 14 Hessian of the distance with respect to [r1 q1 r2 q2] (quaternion normalization
// included), symmetric: exact where the distance is twice differentiable (unique witness points
// and nearest facet), elsewhere the derivative of the reported gradient along the reported
// Jacobians (one of the one-sided choices; for a flat D with its fixed normal, the normal's
// motion is 0). From the witness points' and the normal's Jacobians (src/proximity/
// measure_hessian.hpp with w = -normal). A normal between points turns at 1 / gap: for a gap
// below ~5.6e-309 (subnormal numbers) that rate is not representable, and the normal is held
// fixed as where the cores touch (normal_jacobian 0), so that every entry stays finite.
struct SignedDistanceHessian : SignedDistanceJacobian {
  Eigen::Matrix<double, 3, 14> normal_jacobian =
      Eigen::Matrix<double, 3, 14>::Zero();  // d normal / d[r1 q1 r2 q2]
  Eigen::Matrix<double, 14, 14> hessian = Eigen::Matrix<double, 14, 14>::Zero();
};

SignedDistance signed_distance(const Capsule& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b);
SignedDistance signed_distance(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                               const Pose& pose_b);
SignedDistance signed_distance(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b);
SignedDistance signed_distance(const PaddedPolygon& a, const Pose& pose_a, const PaddedPolygon& b,
                               const Pose& pose_b);
SignedDistance signed_distance(const Shape& a, const Pose& pose_a, const Shape& b,
                               const Pose& pose_b);

SignedDistanceJacobian signed_distance_jacobian(const Capsule& a, const Pose& pose_a,
                                                const Capsule& b, const Pose& pose_b);
SignedDistanceJacobian signed_distance_jacobian(const Capsule& a, const Pose& pose_a,
                                                const PaddedPolygon& b, const Pose& pose_b);
SignedDistanceJacobian signed_distance_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                                const Capsule& b, const Pose& pose_b);
SignedDistanceJacobian signed_distance_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                                const PaddedPolygon& b, const Pose& pose_b);
SignedDistanceJacobian signed_distance_jacobian(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b);

SignedDistanceHessian signed_distance_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                              const Pose& pose_b);

}  // namespace diffpills
