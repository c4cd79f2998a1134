// Which measure the examples' collision constraints keep >= 0.
#pragma once

namespace diffpills::examples {

// The paper's proximity phi, flat (zero gradient) wherever the cores intersect, or the signed
// distance, whose slope points out of the obstacle there too unless the cores' Minkowski
// difference is flat (two shapes in one plane): signed_distance.hpp.
enum class Clearance { kProximity, kSignedDistance };

}  // namespace diffpills::examples
