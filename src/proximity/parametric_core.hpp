// A shape's core as the affine image of a small parameter polytope, in the body frame and in the
// units of a query's frame (pair_frame.hpp), for the reference path (the paper's QPs):
//
//     u(x) = U x + u0,   G x <= h,      world point  p = r + Q(q) u(x)
//
//   capsule, L > 0:  x = theta in [0, 1],  U = [L; 0; 0],  u0 = [-L/2; 0; 0]
//                    (p = theta a + (1 - theta) b with a, b the end points: the paper's EndPoints)
//   capsule, L = 0:  no parameter (a point), u0 = 0
//   polygon:         x = y / e with e = extent(),  U = e [e_x  e_y],  u0 = 0,
//                    n_i' x <= b_i / e over the non-redundant unit-normal rows (n_i, b_i)
//
// Scaling the polygon's parameter by its extent keeps every parameter of order one, so that the
// QP's tolerances mean the same at every scale. One description serves all four shape orderings.
#pragma once

#include <Eigen/Core>

#include "polygon_features.hpp"

namespace diffpills::detail {

struct ParametricCore {
  int dim = 0;                                                          // 0, 1 or 2 parameters
  Eigen::Matrix<double, 3, 2> U = Eigen::Matrix<double, 3, 2>::Zero();  // first dim columns used
  Eigen::Vector3d u0 = Eigen::Vector3d::Zero();
  Eigen::MatrixXd G;  // constraint rows, dim columns
  Eigen::VectorXd h;
  double size = 0.0;  // length scale: the capsule's length or the polygon's extent
};

// A capsule of the given length (a sphere for 0), and a polygon. A core smaller than 2^-500 of the
// frame's unit (3e-151 of the scene's size) is the point at its body origin (see the source).
ParametricCore make_parametric_capsule(double length);
ParametricCore make_parametric_polygon(const PolygonView& polygon);

}  // namespace diffpills::detail
