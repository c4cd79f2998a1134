#include "parametric_core.hpp"

namespace diffpills::detail {
namespace {

// Cores smaller than this, in the frame's units (the scene's size is in [1, 2)), are taken as the
// point at their body origin. The pair's QP is made dimensionless by the larger core size s
// (pair_problem.hpp), so its data hold distance / s, and their squares must stay finite:
// (2 / 2^-500)^2 = 2^1002 < 1.8e308. A core 2^-500 (3e-151) of the scene's size lies far below
// the resolution of the scene's coordinates (2^-52), so the point is exact to rounding.
constexpr double kSmallestResolvedCore = 0x1p-500;

}  // namespace

ParametricCore make_parametric_capsule(double length) {
  ParametricCore core;
  if (length < kSmallestResolvedCore) {
    return core;  // a sphere (or a capsule too short to resolve): the core is the body origin
  }
  core.size = length;
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
  // A polygon too small to resolve (above; its extent may even underflow to 0, and its rows
  // divided by it be 0 / 0) is a point.
  if (extent < kSmallestResolvedCore) return make_parametric_capsule(0.0);
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
