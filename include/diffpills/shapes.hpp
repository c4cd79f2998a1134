// The two primitives and their pose (DESIGN.md sections 1-2).
//
// Padding is a radius on a core, not a new shape: a capsule is a segment padded by R, a padded
// polygon is a planar convex polygon padded by R. All three types validate on construction and
// throw std::invalid_argument whose message starts with the offending field, e.g.
// "capsule.radius: must be >= 0 (got -1)". Once constructed they are immutable values, cheap to
// copy (a polygon shares nothing mutable), and safe to use from any thread.
#pragma once

#include <Eigen/Core>
#include <variant>

namespace diffpills {

// Magnitudes above this are rejected: phi, a squared distance, of such inputs could overflow.
// 1e100 squared is 1e200, still comfortably finite. Every magnitude from 0 to this bound is
// answered correctly (each pair is solved in a frame scaled by a power of two, pair_frame.hpp).
inline constexpr double kMaxMagnitude = 1e100;

// A capsule: the core segment runs along the body x axis from [-L/2, 0, 0] to [L/2, 0, 0] and is
// padded by the radius R. L = 0 is a sphere.
class Capsule {
 public:
  // Throws std::invalid_argument unless 0 <= length, radius <= kMaxMagnitude (finite).
  Capsule(double length, double radius);

  double length() const { return length_; }
  double radius() const { return radius_; }

 private:
  double length_ = 0.0;
  double radius_ = 0.0;
};

// A padded polygon: the core is {y in R^2 : C y <= d} in the body x-y plane, padded by the radius
// R. Requirements (each violation throws std::invalid_argument naming the field):
//   - C is m x 2 and d has m entries, m >= 3, every entry finite;
//   - d > 0: the body origin lies strictly inside the polygon; and d_i / |C_i| >= 1e-300 for
//     every nonzero row (an offset that underflows would put the origin on the boundary);
//   - the polygon is bounded;
//   - 0 <= radius <= kMaxMagnitude.
// Redundant rows (zero rows, rows implied by others, duplicates, rows that cut less than 1e-12 of
// the polygon's size off) are allowed and dropped. A polygon whose vertex lies more than 1e12
// times its largest offset from the origin (nearly parallel or nearly opposite edges meeting far
// away) is reported as unbounded. Slivers are polygons like any other: their vertices are
// computed from the rows as given, to the last digits however nearly opposite the edges, and
// "within the tolerance" of a spike is bevelled, never stretched along it. The constructor
// computes the polygon's vertices once, in O(m log m), by walking the rows in the order of their
// normals' angles around the origin (which lies inside); the test that drops a row is linear in
// the offsets, so offsets from 1e-300 to 1e100 are handled alike.
class PaddedPolygon {
 public:
  PaddedPolygon(const Eigen::MatrixX2d& C, const Eigen::VectorXd& d, double radius);

  // The rows exactly as given, for round trips (serialization, pickling).
  const Eigen::MatrixX2d& constraint_matrix() const { return C_; }
  const Eigen::VectorXd& constraint_offsets() const { return d_; }
  double radius() const { return radius_; }

  // The k non-redundant rows, normalized to unit normals, ordered counterclockwise by the angle of
  // their normal: edge_normals() y <= edge_offsets() describes the same polygon.
  const Eigen::MatrixX2d& edge_normals() const { return normals_; }
  const Eigen::VectorXd& edge_offsets() const { return offsets_; }
  // The row of C each edge comes from (of rows with one normal, the tightest; the first given of
  // equal ones): edge_normals().row(j) = C.row(edge_rows()(j)) / |C.row(edge_rows()(j))|.
  const Eigen::VectorXi& edge_rows() const { return edge_rows_; }
  // The k vertices, counterclockwise; vertex i joins edge i and edge i + 1 (mod k).
  const Eigen::MatrixX2d& vertices() const { return vertices_; }
  // max_i |vertex_i|: the radius of the smallest origin-centred disc holding the core, used as the
  // polygon's length scale for relative tolerances.
  double extent() const { return extent_; }

 private:
  Eigen::MatrixX2d C_;
  Eigen::VectorXd d_;
  double radius_ = 0.0;
  Eigen::MatrixX2d normals_;
  Eigen::VectorXd offsets_;
  Eigen::VectorXi edge_rows_;
  Eigen::MatrixX2d vertices_;
  double extent_ = 0.0;
};

// A rigid-body pose: x_world = r + Q(q) x_body with q = [w, x, y, z] (scalar first). q need not be
// unit; it is normalized wherever it is used, and derivatives include that normalization.
class Pose {
 public:
  // The identity pose.
  Pose();
  // Throws std::invalid_argument ("pose.r: ...", "pose.q: ...") for non-finite entries, |entries|
  // above kMaxMagnitude, or a quaternion whose norm is zero or below 1e-40 (derivatives with
  // respect to q grow as 1 / |q|; below that bound they could overflow for the largest accepted
  // scenes).
  Pose(const Eigen::Vector3d& r, const Eigen::Vector4d& q);

  const Eigen::Vector3d& r() const { return r_; }
  const Eigen::Vector4d& q() const { return q_; }

 private:
  Eigen::Vector3d r_;
  Eigen::Vector4d q_;
};

// Either primitive, for code that handles shapes chosen at run time (the command line, bindings).
using Shape = std::variant<Capsule, PaddedPolygon>;

}  // namespace diffpills
