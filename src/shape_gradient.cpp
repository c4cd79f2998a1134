// Shape-parameter gradients by the envelope theorem (the derivation is in shape_gradient.hpp).
#include "diffpills/shape_gradient.hpp"

#include <cmath>

#include "diffpills/rotation.hpp"
#include "row_scale.hpp"

namespace diffpills {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// d/dL = -|a . w| / 2 with a = Q e_x, the world axis of the segment.
CapsuleShapeGradient capsule_gradient(const Capsule&, const Pose& pose, const Eigen::Vector3d& w,
                                      double radius_derivative) {
  const Eigen::Vector3d axis = rotation_matrix(pose.q()).col(0);
  return {-0.5 * std::abs(axis.dot(w)), radius_derivative};
}

// The multipliers of the rows active at the optimal point, from the cone of the vertex that holds
// -g (g = Q~' w, the objective's gradient in the polygon's plane), and d/dd, d/dC from them.
PolygonShapeGradient polygon_gradient(const PaddedPolygon& polygon, const Pose& pose,
                                      const Eigen::Vector3d& core_point, const Eigen::Vector3d& w,
                                      double radius_derivative) {
  const Eigen::Matrix3d rotation = rotation_matrix(pose.q());
  const Eigen::Vector2d g = (rotation.leftCols<2>().transpose() * w);
  const Eigen::Vector2d y = (rotation.transpose() * (core_point - pose.r())).head<2>();
  const Eigen::MatrixX2d& C = polygon.constraint_matrix();
  PolygonShapeGradient out{Eigen::MatrixX2d::Zero(C.rows(), 2), Eigen::VectorXd::Zero(C.rows()),
                           radius_derivative};
  const Eigen::Vector2d u = -g;
  if (u.x() == 0.0 && u.y() == 0.0) return out;  // a face point: no row is active
  const Eigen::MatrixX2d& normals = polygon.edge_normals();
  const Eigen::Index k = normals.rows();
  // The cones of the vertices partition the directions: vertex j's runs counterclockwise from
  // n_j to n_{j+1}, an angle below pi. Ties on a shared normal go to either cone alike.
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Vector2d first = normals.row(j).transpose();
    const Eigen::Vector2d second = normals.row((j + 1) % k).transpose();
    if (!(cross(first, u) >= 0.0 && cross(u, second) >= 0.0)) continue;
    const double determinant = cross(first, second);  // > 0: consecutive normals turn below pi
    const std::array<double, 2> mu = {cross(u, second) / determinant,
                                      cross(first, u) / determinant};
    const std::array<Eigen::Index, 2> edges = {j, (j + 1) % k};
    for (int side = 0; side < 2; ++side) {
      const int row = polygon.edge_rows()(edges[static_cast<std::size_t>(side)]);
      // The multiplier of the row as given, mu / |C_i| = 2^s mu / |C_i 2^s|: the row scaled
      // exactly (row_scale.hpp, as the polygon normalizes its rows), 2^s applied last. Not
      // C.row(i).norm(), which squares (a row below ~1e-154 made it 0 and the gradient infinite
      // or NaN: a hostile review), nor hypot of the row as given (a subnormal row of 6e-317 had
      // its gradient 1e-7 off the rescaled row's; fuzz_proximity). An entry beyond the largest
      // double is +-infinity (ldexp overflows), never 0 * inf.
      const double mu_side = mu[static_cast<std::size_t>(side)];
      const int shift = detail::row_scale_shift(C(row, 0), C(row, 1));
      const double scaled_norm =
          detail::scaled_row_norm(detail::scaled_row(C(row, 0), C(row, 1), shift));
      out.d(row) = std::ldexp(-mu_side / scaled_norm, shift);
      out.C(row, 0) = std::ldexp(mu_side * y.x() / scaled_norm, shift);
      out.C(row, 1) = std::ldexp(mu_side * y.y() / scaled_norm, shift);
    }
    return out;
  }
  return out;  // not reached: the cones cover every direction
}

ShapeGradient shape_gradient(const Shape& shape, const Pose& pose,
                             const Eigen::Vector3d& core_point, const Eigen::Vector3d& w,
                             double radius_derivative) {
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    return capsule_gradient(*capsule, pose, w, radius_derivative);
  }
  return polygon_gradient(std::get<PaddedPolygon>(shape), pose, core_point, w, radius_derivative);
}

}  // namespace

ProximityShapeGradient proximity_shape_gradient(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b,
                                                const ProximityOptions& options) {
  ProximityShapeGradient out;
  static_cast<Proximity&>(out) = proximity(a, pose_a, b, pose_b, options);
  // phi = |x1 - x2|^2 - (R1 + R2)^2: w = 2 (x1 - x2) on core 1, its negative on core 2 (zero
  // where the cores intersect, where phi is flat).
  const Eigen::Vector3d w = out.cores_intersect
                                ? Eigen::Vector3d::Zero()
                                : Eigen::Vector3d(2.0 * (out.core_points[0] - out.core_points[1]));
  const double radii = std::visit([](const auto& s) { return s.radius(); }, a) +
                       std::visit([](const auto& s) { return s.radius(); }, b);
  out.shape_gradient = {shape_gradient(a, pose_a, out.core_points[0], w, -2.0 * radii),
                        shape_gradient(b, pose_b, out.core_points[1], -w, -2.0 * radii)};
  return out;
}

SignedDistanceShapeGradient signed_distance_shape_gradient(const Shape& a, const Pose& pose_a,
                                                           const Shape& b, const Pose& pose_b) {
  SignedDistanceShapeGradient out;
  static_cast<SignedDistance&>(out) = signed_distance(a, pose_a, b, pose_b);
  // distance = min_{K2} n . x2 - max_{K1} n . x1 - R1 - R2 at the optimal n: w = -n on core 1,
  // +n on core 2.
  out.shape_gradient = {shape_gradient(a, pose_a, out.core_points[0], -out.normal, -1.0),
                        shape_gradient(b, pose_b, out.core_points[1], out.normal, -1.0)};
  return out;
}

}  // namespace diffpills
