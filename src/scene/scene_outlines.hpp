// A scene's primitives as its broadphase reads them, made once when the scene is built: for each,
// its body, its core's points in the body's frame (a segment's two ends or a sphere's centre, a
// polygon's vertices) and its radius, all in two flat arrays. A query then bounds a primitive by
// moving its points with its body's pose alone, touching contiguous memory, and composes a
// primitive's own pose only for the pairs the broadphase finds.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "diffpills/scene.hpp"

namespace diffpills::detail {

struct SceneOutlines {
  struct Primitive {
    int body = 0;
    int shape = 0;
    int first_point = 0, point_count = 0;  // its points: points[first_point, + point_count)
    double radius = 0.0;
  };
  std::vector<Primitive> primitives;  // by body, then shape
  std::vector<Eigen::Vector3d> points;
};

SceneOutlines make_outlines(const std::vector<Body>& bodies);

}  // namespace diffpills::detail
