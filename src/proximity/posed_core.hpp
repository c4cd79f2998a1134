// The three descriptions of a core, from the most static to the most specific:
//   - the shape itself (Capsule, PaddedPolygon): sizes in the units of the inputs;
//   - PosedCore (this file): the core placed in the frame a query is solved in (pair_frame.hpp),
//     with its attitude normalized once; every solver reads it;
//   - ClosestFeature (this file): what a solver returns for one core, its closest point and the
//     directions along which that point's feature leaves it free;
// and, for the reference path only, ParametricCore (parametric_core.hpp): the core as the image
// of a small parameter polytope, the form the paper's QPs are written in.
#pragma once

#include <Eigen/Core>

#include "unit_quaternion.hpp"

namespace diffpills::detail {

// One core in a query's frame: every length divided by the frame's scale, the first shape's body
// origin at the frame's origin.
struct PosedCore {
  Eigen::Vector3d r;        // body origin
  UnitQuaternion attitude;  // q normalized once, and Q(q); derivatives refer to q as given
  double radius = 0.0;
  double size = 0.0;  // a capsule's length, a polygon's extent (also the relative-tolerance scale)
  // The radius in the inputs' units, for the results' radius terms: radius above may be subnormal
  // or zero in the frame (a radius 1e-160 of the scene), this is exact.
  double input_radius = 0.0;
};

// One core's side of a solved pair, in fixed-size form: what every solver (closed form, feature
// enumeration, interior point) hands to the result builder.
//
// The closest point is p = r + Q u with u = body_point in the body frame. The active constraints
// at the solution leave the point free to move along some body-frame directions D (the columns of
// free_directions): none at a polygon vertex, a segment end or a sphere; the edge tangent on a
// polygon edge; the segment axis inside a segment; the body x-y plane inside a polygon face. Any
// basis of that subspace serves. The implicit function theorem then needs no constraint rows at
// all: near the solution the problem is min |p1(xi1) - p2(xi2)|^2 over the free coordinates xi.
struct ClosestFeature {
  Eigen::Vector3d body_point = Eigen::Vector3d::Zero();
  int free_dimensions = 0;  // 0, 1 or 2
  Eigen::Matrix<double, 3, 2> free_directions = Eigen::Matrix<double, 3, 2>::Zero();
};

}  // namespace diffpills::detail
