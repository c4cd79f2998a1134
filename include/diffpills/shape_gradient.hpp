// Derivatives of phi and of the signed distance with respect to the shapes' own parameters
// (DESIGN.md section 2b): a capsule's length and radius, a padded polygon's rows C, offsets d and
// radius, for fitting and designing shapes.
//
// Envelope theorem. Both measures are optimal values over the cores with the poses fixed:
//
//   phi = min { |x1 - x2|^2 : x1 in K1, x2 in K2 } - (R1 + R2)^2,
//   distance = max over unit n of ( min_{x2 in K2} n . x2 - max_{x1 in K1} n . x1 ) - R1 - R2,
//
// (the second is the signed distance of convex cores, apart and in penetration alike). A shape
// parameter moves only the feasible set of its own core, so its derivative is that of the core's
// part of the problem at the optimum: the minimum over x in K of w . x with w = d(measure)/dx at
// the optimal point, held fixed (w = 2 (x1 - x2) for phi on core 1 and 2 (x2 - x1) on core 2;
// w = -normal on core 1 and +normal on core 2 for the distance).
//
// A polygon core is {r + Q [y; 0] : C y <= d}: minimizing g . y over C y <= d with g = Q~' w (Q~
// the first two columns of the rotation), the Lagrangian g . y + lambda' (C y - d) gives
//
//   d/dd_i = -lambda_i,   d/dC_ij = lambda_i y_j,   g + C' lambda = 0,  lambda >= 0,
//
// at the optimal point y. The multipliers live on the rows active there; with the polygon's unit
// rows n_j . y <= b_j (n_j = C_i / |C_i|), -g lies in the normal cone of the optimal point, and
// the cone of vertex j (between n_j and n_{j+1}) holding -g gives -g = mu_j n_j + mu_{j+1}
// n_{j+1} (Cramer's rule), lambda_i = mu_j / |C_i| for the row i that edge j comes from. That
// covers edges too: at a point inside edge j, -g is parallel to n_j and the other mu is 0; inside
// the face g = 0 and every mu is 0. Rows that are redundant (dropped by the polygon's reduction)
// get 0, and of rows given twice the first. d/dd_i and d/dC_i scale as 1 / |C_i|: for a row given
// with |C_i| below ~1e-308 of mu_j (a subnormal row in a scene of unit size, or a row of 1e-281
// with the shapes 1e70 apart) they exceed the largest double, and are then +-infinity (never
// NaN), 2^k times the finite gradient of the row rescaled by 2^k; the polygon's own answers are
// exact. The command answers such a line with an error naming shape_gradient (JSON has no
// infinity).
//
// A capsule core is {r + Q [t; 0; 0] : -L/2 <= t <= L/2}: with g = a . w (a the world axis), the
// multipliers of t <= L/2 and -t <= L/2 give d/dL = g t / L at an end and 0 inside, which is
// -|g| / 2 in both cases (at the end +L/2, g <= 0; at -L/2, g >= 0; inside, g = 0). At L = 0 that
// is the right derivative (the segment growing toward the side that shortens the distance).
//
// Radii: d phi / dR_i = -2 (R1 + R2), d distance / dR_i = -1.
//
// Where the optimum is not unique or an active set changes (a kink), the derivative is that of
// the reported points and normal: one of the one-sided derivatives. Where the cores intersect,
// phi = -(R1 + R2)^2 and only its radius derivatives are nonzero.
#pragma once

#include <Eigen/Core>
#include <array>
#include <variant>

#include "diffpills/proximity.hpp"
#include "diffpills/shapes.hpp"
#include "diffpills/signed_distance.hpp"

namespace diffpills {

struct CapsuleShapeGradient {
  double length = 0.0;
  double radius = 0.0;
};

struct PolygonShapeGradient {
  Eigen::MatrixX2d C;  // m x 2, rows as given
  Eigen::VectorXd d;   // m
  double radius = 0.0;
};

// The gradient of one shape's parameters, the alternative matching the shape's.
using ShapeGradient = std::variant<CapsuleShapeGradient, PolygonShapeGradient>;

struct ProximityShapeGradient : Proximity {
  std::array<ShapeGradient, 2> shape_gradient;  // of phi, shape 1's then shape 2's
};

struct SignedDistanceShapeGradient : SignedDistance {
  std::array<ShapeGradient, 2> shape_gradient;  // of distance
};

// proximity() and the gradients of phi with respect to both shapes' parameters, at the points
// the chosen method returns.
ProximityShapeGradient proximity_shape_gradient(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b,
                                                const ProximityOptions& options = {});

// signed_distance() and the gradients of the distance with respect to both shapes' parameters.
SignedDistanceShapeGradient signed_distance_shape_gradient(const Shape& a, const Pose& pose_a,
                                                           const Shape& b, const Pose& pose_b);

}  // namespace diffpills
