// The paper's Fig. 1 scene: a capsule beside a padded polygon, used by `diffpills demo`.
#pragma once

#include <iosfwd>

#include "diffpills/diffpills.hpp"

namespace diffpills::app {

// A padded regular hexagon lying tilted near the origin and a capsule hovering beside it.
struct Fig1Scene {
  Capsule capsule;
  Pose capsule_pose;
  PaddedPolygon polygon;
  Pose polygon_pose;
};
Fig1Scene fig1_scene();

// Prints phi, the closest points, the normal and the gradient of the scene. Returns 0.
int run_scene_demo(std::ostream& out);

}  // namespace diffpills::app
