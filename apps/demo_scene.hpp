// The paper's Fig. 1 scene: a capsule beside a padded polygon, used by `diffpills demo`.
#pragma once

#include <iosfwd>

namespace diffpills::app {

// Prints phi, the closest points, the normal and the gradient of the scene. Returns 0.
int run_scene_demo(std::ostream& out);

}  // namespace diffpills::app
