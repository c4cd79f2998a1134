// Two intersecting cores: the facet of their Minkowski difference nearest the origin, which gives
// the signed distance's penetration depth, normal and witness points (signed_distance.hpp).
//
// D = K1 - K2 = {x1 - x2 : x1 in K1, x2 in K2} holds 0 when the cores intersect. The translational
// penetration depth, the shortest translation of K2 after which the cores' interiors are apart,
// is the distance from 0 to D's boundary:
//
//     depth = min over unit n of h_D(n),   h_D(n) = max_{x in D} n . x = h_1(n) + h_2(-n)
//
// with h_i the support function of K_i (for every unit n the ray from 0 along n leaves D within
// h_D(n), and the supporting plane at the nearest boundary point is at exactly that distance). The
// minimum is taken at the outward normal of D's nearest facet, and D is a polytope whose facets
// are sums of a face of K1 and a face of -K2 whose normal cones meet, of total dimension 2:
//   - a polygon's own face plus the other core's support set: n = +-N_i, N_i = Q_i e_z. A polygon
//     is a face of itself for both signs, so these are facets whenever D has an interior;
//   - an edge e of K1 plus an edge f of K2, not parallel: n = +-(e x f) / |e x f|, a facet when n
//     lies in both edges' normal cones. In 3-D a polygon edge's normal cone is
//     {alpha N + beta o : beta >= 0}, o its outward normal in the polygon's plane, so an edge of
//     K1 needs n . o >= 0 and an edge of K2 (mirrored in -K2) n . o <= 0; a segment, which is
//     its own edge, admits every n normal to it. Such a facet's h_D(n) = n . (x_e - x_f) for any
//     points x_e, x_f of the two edges: the distance between the edges' lines.
// A vertex plus a vertex or an edge is not 2-D, so there are no other facets. Edge pairs within
// |sin| <= 1e-12 of parallel are left out (the depth moves by at most 1e-12 of the scene's size).
// Every candidate's value is h_D at a facet normal, at least the depth, and the nearest facet is
// among them: their minimum is the depth. The normal-cone tests allow 1e-12 (a cosine, so
// relative): a candidate admitted within it is below the true h_D(n) by at most 1e-12 of the
// scene's size.
//
// Where D is flat (two segments, a segment lying in a polygon's plane, coplanar polygons) it has
// no interior; the candidates +-n of its plane then both give 0, the documented depth.
//
// Witnesses. The nearest facet's nearest point lies on it: x1 - x2 = depth * n with x1, x2 in the
// facet's two features (a face's polygon and the other core's support vertex or edge shifted onto
// it; or the two edges, at the feet of their common normal). So only facets whose nearest point
// lies on them (to the tolerance) are candidates: their minimum is still the depth, and the chosen
// facet always has witnesses that split its nearest point on both cores. (Where cores cross
// nearly coplanar, D is thin and facets a tolerance apart in depth can lie far apart along it;
// choosing among all facets, the tie-break could take one whose nearest point was off it, and its
// witnesses then lay off the cores by up to the scene's size.) An edge pair's witnesses are the
// closest points of the two edges from the backward-stable segment solver: x1 - x2 is a point of
// the facet, so of D's boundary, and |x1 - x2| >= depth. It is accepted when it points along n and
// |x1 - x2| <= (value + its rounding error) (1 + 1e-9) + tolerance, and the facet's depth and
// normal are then taken from it: accurate also where the edges are nearly parallel and e x f is
// not. Should no candidate's witnesses pass within 1e-9 of the smallest value (never seen; it
// would take rounding to move the nearest facet's point off it), that value stands with no
// witnesses, and the caller uses the closest points.
//
// Ties (values within the frame's tolerance) go to a polygon's face over an edge pair (a face's
// witnesses are well conditioned; an edge pair's nearly parallel to the face makes a sliver facet
// whose nearest point a tolerance can move off it, found by fuzz_proximity); then to the normal
// pointing most from core 1's body origin to core 2's, n . (r2 - r1), which turns with the scene
// and flips with the order of the shapes; then to the one most along core 1's Q e_z; then to the
// first found (faces of core 1, faces of core 2, edge pairs in order).
//
// Cost: O(m) for a segment and a polygon of m vertices; two polygons of up to 32 x 32 vertex pairs
// have every edge pair visited (nothing is allocated); larger pairs search bounding hierarchies of
// their edge chains (edge_chain_tree.hpp) for the edge pairs that can hold a facet's nearest point
// within the depth found so far, about O((m1 + m2) log) instead of the m1 m2 facets D has.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>

#include "core_outline.hpp"

namespace diffpills::detail {

struct DeepestFacet {
  enum class Kind {
    kNone,   // no candidate: two parallel segments, or a sphere with a segment or a sphere
    kFace,   // core face_core's face
    kEdges,  // edge edges[0] of core 1 and edges[1] of core 2
  };
  Kind kind = Kind::kNone;
  double depth = 0.0;                                // h_D(normal), in the frame's units
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, outward from D: from core 1 to core 2
  int face_core = 0;
  std::array<Eigen::Index, 2> edges = {0, 0};
  // The points x1 of core 1 and x2 of core 2 on the facet with x1 - x2 = depth * normal: its
  // nearest point split into the two cores (the middle of the set of such pairs when it is not
  // one pair: the middle of an edge's part over a face). Unset where the depth is within the
  // tolerance (touching, or a flat D: the closest points serve) and in the header's fallback.
  std::optional<std::array<ClosestFeature, 2>> witnesses;
};

// Which edge pairs the search visits: those the edge chains' hierarchies leave (the default: every
// pair up to 32 x 32), or every pair (for tests of the hierarchies).
enum class EdgePairVisits { kPruned, kEvery };

// `tolerance`: ties and touching, in the frame's units; the search's rounding allowances are
// relative to it (the frame's, or two polygons' own: pair_setup.hpp, search_tolerances).
DeepestFacet deepest_facet(const CoreOutline& a, const CoreOutline& b, double tolerance,
                           EdgePairVisits visits = EdgePairVisits::kPruned);

// e x f for unit vectors e and f, computed as e x (f - e) (or e x (f + e) when they point apart):
// the same vector, but for nearly parallel e and f the difference f - e is exact and the product
// keeps full relative accuracy, where e x f itself cancels to an error of ~1e-16 / |e x f| in
// direction (fuzz_proximity: two polygons crossing at 2e-11 rad got a facet normal 1e-5 off and
// a depth of the polygons' size instead of 2e-11 of it).
Eigen::Vector3d stable_cross(const Eigen::Vector3d& e, const Eigen::Vector3d& f);

}  // namespace diffpills::detail
