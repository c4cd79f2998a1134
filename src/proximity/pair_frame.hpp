// The frame every pair is solved in: lengths divided by a power of two near the scene's size.
//
// A query's inputs may be of any magnitude from 0 to 1e100 (and the whole scene may be scaled
// anywhere in that range), but a solver that squares lengths, or compares squared distances,
// over- or underflows at either end. So each query is solved in a frame where the scene's size
// (the largest of the two core sizes, the two radii and the distance between the body origins) is
// in [1, 2): every length is divided by scale = 2^e, and the body origin of shape a is moved to the
// frame's origin. Dividing by a power of two is exact, so a scene scaled by 2^k is solved in
// exactly the same normalized frame, bit for bit, and its results scale exactly: phi by 2^(2k),
// points by 2^k, the gradient's position part by 2^k and its quaternion part by 2^(2k).
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

struct PairFrame {
  double scale = 1.0;          // a length in the frame times scale is a length of the inputs
  double inverse_scale = 1.0;  // 1 / scale, exact (also a power of two)
  // The scene's size in the frame, rounded down to a power of two: 1, except for a scene below
  // 2^-1000 (of subnormal numbers), whose frame stops at 2^-1000 (1 / scale must stay finite) so
  // that its size in the frame is 2^-74 .. 2^-1. Rules that compare with "the scene's size in the
  // frame" (contact_normal.hpp) use this rather than assume 1.
  double unit = 1.0;
  // Two cores closer than this intersect, and a point closer than this to a polygon's boundary
  // is on it: the relative intersection tolerance, 1e-12 of the scene's size, in the frame's
  // units.
  double tolerance = 0.0;
  // Two candidates for the closest pair whose distances differ by less than this tie (and a
  // candidate standing for a whole interval wins, fast_paths.hpp): 2e-12 of the larger core's
  // size (the most by which the height of a feature counted as parallel, |sin| <= 1e-12, can
  // vary) plus 64 ulps of the scene's size (the rounding of coordinates as far out as the scene
  // reaches). Not 1e-12 of the scene's size: a scene's size includes the distance between the
  // shapes, and for two shapes a distance V apart, candidates h and H to the side of each other
  // differ in distance only by (H^2 - h^2) / 2V, so that ties judged by the scene's size took a
  // vertex of the far side of a polygon 1e-6 of the scene away (found by fuzz_proximity).
  double tie_tolerance = 0.0;
};

// The tolerances the bare cores would be solved with, in this frame's units: those of
// make_pair_frame without the radii, 1e-12 of the cores' own scene (the larger core size and the
// distance between the body origins) and 2e-12 of the larger core plus 64 ulps of that scene,
// where they are finer than the frame's. They are where the radii make the scene: the coordinates
// of a pair's cores, taken from shape a's body origin, reach only the cores' scene, and their
// rounding with it; the radii play no part in which core points are closest. Searches whose pruning
// is only as fine as the tolerance need them there: a needle 4e-11 long and 4e-14 wide beside radii
// of 1 lies wholly within 1e-12 of the scene of any plane along it, and discs 5e-10 across beside
// radii of 1 have ~1,400 of 10^5 vertices within it of a support line (polygon_windows.cpp,
// penetration.hpp). Cores below 1e-100 of the frame's units keep the frame's: the searches form
// products of two core lengths (squared distances, values along a direction), which must stay far
// from underflow (below ~1e-154 they lose every digit). (The signed distance solves such cores,
// down to 1e-140, in a frame of their own instead: signed_distance.cpp, solve_at_cores_scale.)
struct CoreTolerances {
  double intersection = 0.0;
  double tie = 0.0;
};
CoreTolerances core_tolerances(const PairFrame& frame, double size_a, double size_b,
                               double distance);

// size_* is a core's length scale (a capsule's length, a polygon's extent), radius_* its padding.
PairFrame make_pair_frame(double size_a, double radius_a, double size_b, double radius_b,
                          const Eigen::Vector3d& r_a, const Eigen::Vector3d& r_b);

}  // namespace diffpills::detail
