#include "parametric_core.hpp"

namespace diffpills::detail {

ParametricCore make_parametric_capsule(double length) {
  ParametricCore core;
  core.size = length;
  if (length == 0.0) {
    return core;  // a sphere: the core is the body origin
  }
  core.dim = 1;
  core.U(0, 0) = length;
  core.u0(0) = -0.5 * length;
  core.G.resize(2, 1);
  core.G << 1.0, -1.0;
  core.h.resize(2);
  core.h << 1.0, 0.0;
  return core;
}

ParametricCore make_parametric_polygon(const PolygonView& polygon) {
  const double extent = polygon.extent();
  // A polygon smaller than the smallest double in the frame's units (2^-1074 of the scene's size:
  // a polygon of extent 1e-317 beside a shape 1e53 away) is a point there; the rows divided by
  // its extent would be 0 / 0.
  if (extent == 0.0) return make_parametric_capsule(0.0);
  ParametricCore core;
  const Eigen::Index k = polygon.size();
  core.dim = 2;
  core.size = extent;
  core.U(0, 0) = extent;
  core.U(1, 1) = extent;
  core.G.resize(k, 2);
  core.h.resize(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    core.G.row(j) = polygon.normal(j).transpose();
    core.h(j) = polygon.offset(j) / extent;
  }
  return core;
}

}  // namespace diffpills::detail
