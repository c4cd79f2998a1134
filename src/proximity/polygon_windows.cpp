#include "polygon_windows.hpp"

#include <algorithm>
#include <limits>
#include <vector>

namespace diffpills::detail {
namespace {

// A set of a polygon's vertex indices. Vertices enter with their two neighbours, so that the
// edges at every window vertex are in the window too.
class Window {
 public:
  explicit Window(Eigen::Index size) : member_(static_cast<std::size_t>(size), 0) {}
  // Adds vertex i and its neighbours; returns true if anything was new.
  bool add(Eigen::Index i) {
    const auto k = static_cast<Eigen::Index>(member_.size());
    bool grew = false;
    for (const Eigen::Index j : {i == 0 ? k - 1 : i - 1, i, i + 1 == k ? 0 : i + 1}) {
      char& member = member_[static_cast<std::size_t>(j)];
      if (member == 0) {
        member = 1;
        members_.push_back(j);
        grew = true;
      }
    }
    return grew;
  }
  // The members in increasing (counterclockwise) order.
  std::vector<Eigen::Index> indices() const {
    std::vector<Eigen::Index> out = members_;
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::vector<char> member_;  // a flag per vertex of the polygon
  std::vector<Eigen::Index> members_;
};

// A linear function f along a convex polygon's boundary is unimodal: from any vertex, stepping to
// a neighbour with a larger value leads to the maximum (the vertices of an edge perpendicular to
// the gradient tie; either is a maximum). `f(i)` is the value at vertex i; `from` the start.
template <class Function>
Eigen::Index climb(Eigen::Index from, Eigen::Index size, const Function& f) {
  const auto next = [size](Eigen::Index i) { return i + 1 == size ? 0 : i + 1; };
  const auto previous = [size](Eigen::Index i) { return i == 0 ? size - 1 : i - 1; };
  double value = f(from);
  for (Eigen::Index step = 0; step < size; ++step) {
    if (f(next(from)) > value) {
      from = next(from);
    } else if (f(previous(from)) > value) {
      from = previous(from);
    } else {
      break;
    }
    value = f(from);
  }
  return from;
}

// The arc of vertices around the maximum `top` of f whose values are within `margin` of it
// (contiguous, by unimodality), or whole = true if that is every vertex.
struct Arc {
  Eigen::Index first = 0, count = 0;  // counterclockwise from first
  bool whole = false;
};

template <class Function>
Arc arc_around(Eigen::Index top, Eigen::Index size, double margin, const Function& f) {
  const double floor = f(top) - margin;
  Eigen::Index forward = 0, backward = 0;
  while (forward + 1 < size && f((top + forward + 1) % size) >= floor) ++forward;
  while (backward + forward + 1 < size && f((top - backward - 1 + size) % size) >= floor) {
    ++backward;
  }
  const Eigen::Index count = forward + backward + 1;
  return {(top - backward + size) % size, count, count == size};
}

bool add_arc(Window& window, const Arc& arc, Eigen::Index size) {
  bool grew = false;
  for (Eigen::Index step = 0; step < arc.count; ++step) {
    grew = window.add((arc.first + step) % size) || grew;
  }
  return grew;
}

}  // namespace

// GJK's idea with exact steps. The closest pair of two windows' convex hulls (sub-polygons of A
// and B) is found exactly by the enumeration; its difference d = p2 - p1 then either certifies
// it for the whole polygons, by the separating planes
//   max_{x in A} x . d <= p1 . d + slack   and   min_{y in B} y . d >= p2 . d - slack
// (then |y - x| >= (y - x) . d / |d| >= |d| - 2 slack / |d| for every x in A, y in B), or names
// the support vertices that violate it, which are not in the windows yet (the windows' own
// supports satisfy it, the sub-problem being solved exactly). Either way the vertices within
// 2 slack of the support planes are added: they hold every closest point and every tie of a
// certified pair, and the violators of an uncertified one. The windows only grow, so the loop
// ends; it ends when nothing is added, with a certified pair whose ties are all in the windows.
// slack = tie_tolerance |d|: the tolerance by which the sub-problems judge ties (Best::choice
// takes an interval over the best point only within it), so that every tie is in the windows. It
// was the larger of this and the intersection tolerance, 1e-12 of the scene, which for unit
// polygons 1e8 apart is 1e-4, far above the 64 ulps of the distance at which their features
// really tie: polygons tilted 1e-5 rad had whole windows, swept within that band (0.18 s at 2,000
// vertices, 8.3 s at 16,000; a hostile review); now 0.3 and 2.3 ms.
//
// d's rounding. p1 and p2 carry errors of a few ulps of their own size, so d is off by up to
// delta = 64 eps (|p1| + |p2|), and a polygon's values x . d by up to 2 extent delta: for a gap far
// below the polygons' size that is far above the slack, and the supports, the window's own
// included, are then decided by rounding (two unit 600-gons 1e-9 apart, 1e-10 rad from parallel,
// came out 9.43e-10 apart instead of 9.00e-10: the windows held B's vertex the rounding chose, not
// its lowest). Each polygon's margin therefore adds 2 extent delta. Where that takes in both
// polygons whole (faces facing each other closer than rounding can tell directions apart), both
// windows become the whole polygons and the enumeration (its search of large windows) decides.
//
// Supports are found by climbing from the previous ones along the boundary, so that an iteration
// costs the windows' enumeration plus the support's movement, not the polygons' size; each
// iteration sorts the window's members. Measured: ~10 to 20 iterations for
// two random 10^5-gons, windows of a few dozen vertices; a support face that is a whole polygon
// (a vertex over the other's face) brings the whole polygon in, for one or two final iterations.
std::array<ClosestFeature, 2> closest_separated_by_windows(const PolygonView& a,
                                                           const PolygonView& b,
                                                           const PolygonPairFrame& frame,
                                                           const CarriedPolygon<PolygonView>& W,
                                                           double tolerance, double tie_tolerance) {
  Window window_a(a.size()), window_b(b.size());
  // First guess: the supports along the line between the body origins (each inside its polygon).
  Eigen::Vector3d d = frame.b_origin_in_a;
  Eigen::Index top_a = 0, bottom_b = 0;
  const auto along_a = [&](Eigen::Index i) { return a.vertex(i).dot(d.head<2>()); };
  const auto against_b = [&](Eigen::Index j) { return -W[j].dot(d); };  // max of -y . d
  top_a = climb(top_a, a.size(), along_a);
  bottom_b = climb(bottom_b, b.size(), against_b);
  window_a.add(top_a);
  window_b.add(bottom_b);
  while (true) {
    const SubPolygon sub_a(a, window_a.indices()), sub_b(b, window_b.indices());
    const CarriedPolygon<SubPolygon> sub_W(sub_b, frame.b_in_a, frame.b_origin_in_a);
    const CarriedPolygon<SubPolygon> sub_X(sub_a, frame.b_in_a.transpose(), frame.a_origin_in_b);
    std::array<ClosestFeature, 2> sides =
        closest_separated(sub_a, sub_b, frame, sub_W, sub_X, tolerance, tie_tolerance);
    const Eigen::Vector3d p1 = sides[0].body_point;
    const Eigen::Vector3d p2 = frame.b_in_a * sides[1].body_point + frame.b_origin_in_a;
    d = p2 - p1;
    const double slack = tie_tolerance * d.norm();
    const double rounding = 64 * std::numeric_limits<double>::epsilon() * (p1.norm() + p2.norm());
    const double margin_a = 2.0 * (slack + 2.0 * a.extent() * rounding);
    const double margin_b = 2.0 * (slack + 2.0 * b.extent() * rounding);
    top_a = climb(top_a, a.size(), along_a);
    bottom_b = climb(bottom_b, b.size(), against_b);
    // A polygon whose extent is within the margin (a speck, far smaller than the scene) is taken
    // whole: a window of it would have chords between vertices that its few resolved digits, or
    // underflow, can make coincide, and a chord of no length bounds nothing.
    const Arc arc_a = a.extent() <= margin_a ? Arc{0, a.size(), false}
                                             : arc_around(top_a, a.size(), margin_a, along_a);
    const Arc arc_b = b.extent() <= margin_b ? Arc{0, b.size(), false}
                                             : arc_around(bottom_b, b.size(), margin_b, against_b);
    // A whole polygon within the margin is a face facing the other along its normal: its windows
    // keep only the support (enough for the certificate), and once the other side's arc is in
    // its window the answer is the other's support over that whole face. Both whole: both taken
    // whole (see d's rounding above).
    const bool both_whole = arc_a.whole && arc_b.whole;
    bool grew_a =
        arc_a.whole && !both_whole ? window_a.add(top_a) : add_arc(window_a, arc_a, a.size());
    bool grew_b =
        arc_b.whole && !both_whole ? window_b.add(bottom_b) : add_arc(window_b, arc_b, b.size());
    std::array<ClosestFeature, 2> over_face;
    if (arc_a.whole && !arc_b.whole && !grew_b) {
      if (closest_over_face(a, sub_b, sub_W, true, tolerance, tie_tolerance, over_face)) {
        return over_face;
      }
      grew_a = add_arc(window_a, arc_a, a.size());  // the support over A's boundary: its edges
    }
    if (arc_b.whole && !arc_a.whole && !grew_a) {
      if (closest_over_face(b, sub_a, sub_X, false, tolerance, tie_tolerance, over_face)) {
        return over_face;
      }
      grew_b = add_arc(window_b, arc_b, b.size());
    }
    if (!grew_a && !grew_b) {
      // The certificate, checked once nothing is left to add: where the distance is flat along
      // both rims (two 51-gons 1e-9 rad from parallel, rims over each other) the sub-problem's
      // pair can be optimal in its windows to 4e-17 and still fail it with the supports inside,
      // 6e-12 of the scene from the closest pair and different in the two orders (found by
      // fuzz_proximity). Then every vertex between the pair's value and the support's joins.
      const double excess_a = along_a(top_a) - p1.head<2>().dot(d.head<2>());
      const double excess_b = against_b(bottom_b) + p2.dot(d);
      if (excess_a > 0.5 * margin_a && !arc_a.whole) {
        grew_a =
            add_arc(window_a, arc_around(top_a, a.size(), margin_a + excess_a, along_a), a.size());
      }
      if (excess_b > 0.5 * margin_b && !arc_b.whole) {
        grew_b = add_arc(window_b, arc_around(bottom_b, b.size(), margin_b + excess_b, against_b),
                         b.size());
      }
      if (!grew_a && !grew_b) return sides;
    }
  }
}

}  // namespace diffpills::detail
