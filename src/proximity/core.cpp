#include "core.hpp"

namespace diffpills::detail {

Core make_core(const Capsule& capsule) {
  Core core;
  core.size = capsule.length();
  if (capsule.length() == 0.0) {
    return core;  // a sphere: the core is the body origin
  }
  core.dim = 1;
  core.U(0, 0) = capsule.length();
  core.u0(0) = -0.5 * capsule.length();
  core.G.resize(2, 1);
  core.G << 1.0, -1.0;
  core.h.resize(2);
  core.h << 1.0, 0.0;
  return core;
}

Core make_core(const PaddedPolygon& polygon) {
  Core core;
  core.dim = 2;
  core.size = polygon.extent();
  core.U(0, 0) = polygon.extent();
  core.U(1, 1) = polygon.extent();
  core.G = polygon.edge_normals();
  core.h = polygon.edge_offsets() / polygon.extent();
  return core;
}

}  // namespace diffpills::detail
