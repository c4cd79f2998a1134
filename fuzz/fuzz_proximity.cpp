// libFuzzer target: bytes -> two shapes and poses -> every query the library offers, with the
// invariants every answer must keep (issue 9).
//
// Decoding. Numbers come from the bytes in four ways, so that the fuzzer reaches both generic and
// hostile inputs quickly: any double (inf and NaN included), a small multiple of 1/8 (exact, so
// that shapes line up: parallel, coplanar, stacked, touching), a signed power of two of any
// exponent (1e-300 .. 1e100 and beyond the accepted range), or one of a list of edge values.
// Attitudes are drawn the same way, or from the 24 rotations of a cube (aligned features).
//
// Checked, for every ordering of the two shapes and both methods:
//   - only documented exceptions: std::invalid_argument from construction (bad sizes, unbounded
//     polygons, zero or non-finite quaternions), SolverError from the interior-point method;
//   - finite phi, points, gradient and Jacobians; a unit normal; phi >= -(R1 + R2)^2;
//   - swap symmetry: proximity(b, a) has the same phi and the points swapped (two polygons: to
//     1e-10 of the scene and the body origins' magnitudes, ties and tolerance-decided cases too);
//   - the interior-point reference agrees with the default path on phi (one pair in four);
//   - proximity_batch over a few rows and threads equals the single calls bit for bit (two
//     capsules: to 1e-12 of the scene, the vector kernel, with signed_distance_batch too);
//   - the signed distance: finite, a unit normal, swap symmetry (two polygons: the witnesses
//     swapped and the normals opposite, to 1e-10 and rounding), points[1] - points[0] =
//     distance * normal with the witnesses on the cores, and agreement with proximity()'s
//     closest points where the cores are apart (distance + R1 + R2 = |p1 - p2|) or at most
//     -(R1 + R2) where they intersect;
//   - second order and shapes (one pair in two): proximity_hessian and signed_distance_hessian
//     repeat the first-order answer bit for bit (the Jacobians too) and give a finite, exactly
//     symmetric Hessian (and a finite normal Jacobian), which proximity_with_hessian repeats
//     with its Proximity (every field ==); two capsules' Hessian agrees with the
//     general pipeline's; the shape gradients have a row per given row, no NaN and the same
//     phi / distance as the plain calls, and are finite except where a polygon row's 1 / |C_i|
//     carries them beyond the double range (confirmed with the rows rescaled to unit length).
#include <fuzzer/FuzzedDataProvider.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "proximity/capsule_proximity.hpp"

namespace {

using diffpills::Capsule;
using diffpills::PaddedPolygon;
using diffpills::Pose;
using diffpills::Shape;

// The decoded inputs of the current run, printed with a failure so that it can be reproduced.
std::string g_inputs;

std::string describe(const Shape& shape, const Pose& pose) {
  std::string text;
  char number[32];
  const auto add = [&](double value) {
    std::snprintf(number, sizeof number, "%.17g, ", value);
    text += number;
  };
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    text += "Capsule(";
    add(capsule->length());
    add(capsule->radius());
  } else {
    const auto& polygon = std::get<PaddedPolygon>(shape);
    // A regular polygon of many rows is described by its first rows (its d are all equal).
    const Eigen::Index rows = std::min<Eigen::Index>(polygon.constraint_matrix().rows(), 64);
    text += "PaddedPolygon(" + std::to_string(polygon.constraint_matrix().rows()) + " rows, C = [";
    for (Eigen::Index i = 0; i < rows; ++i) {
      add(polygon.constraint_matrix()(i, 0));
      add(polygon.constraint_matrix()(i, 1));
    }
    text += "], d = [";
    for (Eigen::Index i = 0; i < rows; ++i) {
      add(polygon.constraint_offsets()(i));
    }
    text += "], radius = ";
    add(polygon.radius());
  }
  text += ") at r = [";
  for (int i = 0; i < 3; ++i) add(pose.r()(i));
  text += "], q = [";
  for (int i = 0; i < 4; ++i) add(pose.q()(i));
  return text + "]\n";
}

[[noreturn]] void violated(const char* what, double value) {
  std::fprintf(stderr, "invariant violated: %s (%.17g)\n%s", what, value, g_inputs.c_str());
  std::abort();
}

void check(bool holds, const char* what, double value = 0.0) {
  if (!holds) violated(what, value);
}

double take_number(FuzzedDataProvider& data) {
  static constexpr std::array<double, 14> kEdges = {0.0,
                                                    -0.0,
                                                    1.0,
                                                    -1.0,
                                                    1e-300,
                                                    5e-324,
                                                    1e100,
                                                    -1e100,
                                                    1.0000000000000002e100,
                                                    1e-100,
                                                    2.2e-308,
                                                    1e300,
                                                    0.5,
                                                    std::numeric_limits<double>::quiet_NaN()};
  switch (data.ConsumeIntegralInRange<int>(0, 4)) {
    case 0: {
      double value = 0.0;
      const auto bytes = data.ConsumeBytes<std::uint8_t>(sizeof value);
      std::copy(bytes.begin(), bytes.end(), reinterpret_cast<std::uint8_t*>(&value));
      return value;
    }
    case 1:
    case 2:
      return data.ConsumeIntegralInRange<int>(-24, 24) / 8.0;
    case 3:
      return std::ldexp(data.ConsumeIntegralInRange<int>(-3, 3),
                        data.ConsumeIntegralInRange<int>(-1100, 1100));
    default:
      return data.PickValueInArray(kEdges);
  }
}

Eigen::Vector4d take_quaternion(FuzzedDataProvider& data) {
  if (data.ConsumeBool()) {
    // Products of quarter turns about the axes: the 24 rotations of a cube, and their negatives.
    static const double h = std::sqrt(0.5);
    static const std::array<Eigen::Vector4d, 10> kQuarterTurns = {
        Eigen::Vector4d(1, 0, 0, 0),  Eigen::Vector4d(h, h, 0, 0),
        Eigen::Vector4d(h, 0, h, 0),  Eigen::Vector4d(h, 0, 0, h),
        Eigen::Vector4d(0, 1, 0, 0),  Eigen::Vector4d(0, 0, 1, 0),
        Eigen::Vector4d(0, 0, 0, 1),  Eigen::Vector4d(0.5, 0.5, 0.5, 0.5),
        Eigen::Vector4d(h, -h, 0, 0), Eigen::Vector4d(-0.5, 0.5, -0.5, 0.5)};
    return data.PickValueInArray(kQuarterTurns);
  }
  Eigen::Vector4d q;
  for (int i = 0; i < 4; ++i) q(i) = take_number(data);
  return q;
}

Pose take_pose(FuzzedDataProvider& data) {
  Eigen::Vector3d r;
  for (int i = 0; i < 3; ++i) r(i) = take_number(data);
  return Pose(r, take_quaternion(data));
}

// A capsule, or a polygon of 0 to 40 rows (sometimes a regular polygon of up to 120 rows, for the
// large-polygon path, which starts above 32 x 32 vertex pairs), from numbers or from unit normals
// at angles taken from the bytes.
Shape take_shape(FuzzedDataProvider& data) {
  if (data.ConsumeBool()) return Capsule(take_number(data), take_number(data));
  const double radius = take_number(data);
  if (data.ConsumeIntegralInRange<int>(0, 7) == 0) {
    const int count = data.ConsumeIntegralInRange<int>(3, 120);
    const double offset = take_number(data);
    Eigen::MatrixX2d C(count, 2);
    for (int i = 0; i < count; ++i) {
      C.row(i) << std::cos(2 * M_PI * i / count), std::sin(2 * M_PI * i / count);
    }
    return PaddedPolygon(C, Eigen::VectorXd::Constant(count, offset), radius);
  }
  const int rows = data.ConsumeIntegralInRange<int>(0, 40);
  Eigen::MatrixX2d C(rows, 2);
  Eigen::VectorXd d(rows);
  const bool by_angle = data.ConsumeBool();
  for (int i = 0; i < rows; ++i) {
    if (by_angle) {
      const double angle = 2 * M_PI * data.ConsumeIntegralInRange<int>(0, 4095) / 4096.0;
      C.row(i) << std::cos(angle), std::sin(angle);
    } else {
      C.row(i) << take_number(data), take_number(data);
    }
    d(i) = take_number(data);
  }
  return PaddedPolygon(C, d, radius);
}

double radius_of(const Shape& shape) {
  return std::visit([](const auto& s) { return s.radius(); }, shape);
}

double size_of(const Shape& shape) {
  if (const auto* capsule = std::get_if<Capsule>(&shape)) return capsule->length();
  return std::get<PaddedPolygon>(shape).extent();
}

Eigen::Index rows_of(const Shape& shape) {
  const auto* polygon = std::get_if<PaddedPolygon>(&shape);
  return polygon == nullptr ? 0 : polygon->vertices().rows();
}

// How far a world point lies off a shape's core (up to a factor of order one for a polygon: the
// larger of its height over the plane and its largest row violation).
double off_core(const Shape& shape, const Pose& pose, const Eigen::Vector3d& point) {
  const Eigen::Vector3d y = diffpills::rotation_matrix(pose.q()).transpose() * (point - pose.r());
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    const double along = std::max(std::abs(y.x()) - 0.5 * capsule->length(), 0.0);
    return std::hypot(along, std::hypot(y.y(), y.z()));
  }
  const auto& polygon = std::get<PaddedPolygon>(shape);
  double outside = 0.0;
  for (Eigen::Index i = 0; i < polygon.edge_normals().rows(); ++i) {
    outside = std::max(outside,
                       polygon.edge_normals().row(i).dot(y.head<2>()) - polygon.edge_offsets()(i));
  }
  return std::max(std::abs(y.z()), outside);
}

void check_result(const diffpills::ProximityJacobian& result, double radii) {
  check(std::isfinite(result.phi), "phi is finite", result.phi);
  check(result.gradient.allFinite(), "gradient is finite");
  check(result.core_points[0].allFinite() && result.core_points[1].allFinite(),
        "core points are finite");
  check(result.points[0].allFinite() && result.points[1].allFinite(), "points are finite");
  check(result.core_points_jacobian.allFinite() && result.points_jacobian.allFinite(),
        "Jacobians are finite");
  check(std::abs(result.normal.norm() - 1.0) <= 1e-14, "normal is unit", result.normal.norm());
  // phi + (R1 + R2)^2 is a squared distance.
  check(result.phi >= -radii * radii * (1.0 + 1e-15), "phi >= -(R1 + R2)^2", result.phi);
}

void compare_with_interior_point(const Shape& a, const Pose& pose_a, const Shape& b,
                                 const Pose& pose_b, double phi, double radii, double scene) {
  try {
    const diffpills::ProximityJacobian reference =
        diffpills::proximity_jacobian(a, pose_a, b, pose_b, {diffpills::Method::kInteriorPoint});
    check_result(reference, radii);
    check(std::abs(reference.phi - phi) <= 1e-6 * scene * scene,
          "interior point agrees with the default path", reference.phi - phi);
  } catch (const diffpills::SolverError&) {
    // Documented: the interior-point method reports that it did not converge.
  }
}

// The two orders of the arguments give core points that are each other's swapped, to 1e-10 of
// what the results round in: the scene, and coordinates as large as the body origins. Returns
// that reach.
double check_points_swapped(const std::array<Eigen::Vector3d, 2>& ab,
                            const std::array<Eigen::Vector3d, 2>& ba, const Pose& pose_a,
                            const Pose& pose_b, double scene, const char* what) {
  const double reach =
      scene + std::max(pose_a.r().lpNorm<Eigen::Infinity>(), pose_b.r().lpNorm<Eigen::Infinity>());
  const double apart = std::max((ab[0] - ba[1]).lpNorm<Eigen::Infinity>(),
                                (ab[1] - ba[0]).lpNorm<Eigen::Infinity>());
  check(apart <= 1e-10 * reach + 8 * std::numeric_limits<double>::denorm_min(), what,
        apart / reach);
  return reach;
}

void check_signed_distance(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                           const diffpills::ProximityJacobian& proximity, double radii,
                           double scene) {
  const diffpills::SignedDistanceJacobian ab =
      diffpills::signed_distance_jacobian(a, pose_a, b, pose_b);
  const diffpills::SignedDistance ba = diffpills::signed_distance(b, pose_b, a, pose_a);
  check(std::isfinite(ab.distance) && std::isfinite(ba.distance), "signed distance is finite",
        ab.distance);
  check(ab.gradient.allFinite() && ab.points_jacobian.allFinite() &&
            ab.core_points_jacobian.allFinite(),
        "signed distance derivatives are finite");
  check(ab.points[0].allFinite() && ab.points[1].allFinite(), "witness points are finite");
  check(std::abs(ab.normal.norm() - 1.0) <= 1e-14, "signed distance normal is unit",
        ab.normal.norm());
  // (With a floor of a few subnormals: a scene of subnormal numbers has a tolerance of zero.)
  const double tolerance = 1e-10 * scene + 8 * std::numeric_limits<double>::denorm_min();
  // World points are only representable to a few ulps of their own magnitude (a scene of size 1e70
  // at z = 1e100 has its points to ~1e84), and so is anything computed from them.
  const double representable =
      8 * std::numeric_limits<double>::epsilon() *
      std::max({ab.points[0].lpNorm<Eigen::Infinity>(), ab.points[1].lpNorm<Eigen::Infinity>(),
                proximity.core_points[0].lpNorm<Eigen::Infinity>(),
                proximity.core_points[1].lpNorm<Eigen::Infinity>()});
  check(std::abs(ab.distance - ba.distance) <= tolerance, "swap symmetry of the signed distance",
        ab.distance - ba.distance);
  // Two polygons are solved with the same one first in both orders (signed_distance.cpp), so
  // their witnesses swap and their normals are opposite, where the cores' normal is free (coplanar
  // polygons) too. Not for two identical polygons: where their relative pose is its own inverse
  // (a half turn), the rigid motion that carries each onto the other turns one order of the
  // arguments into the other, and penetration facets that tie (symmetric under it) are decided
  // by a rule that no choice can make both swap-symmetric and rigid-motion invariant.
  const auto* polygon_a = std::get_if<PaddedPolygon>(&a);
  const auto* polygon_b = std::get_if<PaddedPolygon>(&b);
  if (polygon_a != nullptr && polygon_b != nullptr &&
      (polygon_a->vertices().rows() != polygon_b->vertices().rows() ||
       polygon_a->vertices() != polygon_b->vertices() ||
       polygon_a->radius() != polygon_b->radius())) {
    const double reach = check_points_swapped(ab.core_points, ba.core_points, pose_a, pose_b, scene,
                                              "two polygons: both orders give the same witnesses");
    // A normal taken from the points turns by their rounding over the gap (cores just apart).
    const double gap = std::abs(ab.distance + radii);
    check((ab.normal + ba.normal).lpNorm<Eigen::Infinity>() <=
              1e-10 + 1e3 * std::numeric_limits<double>::epsilon() * reach / gap,
          "two polygons: both orders give opposite normals",
          (ab.normal + ba.normal).lpNorm<Eigen::Infinity>());
  }

  check((ab.points[1] - ab.points[0] - ab.distance * ab.normal).stableNorm() <=
            tolerance + representable,
        "points[1] - points[0] = distance * normal",
        (ab.points[1] - ab.points[0] - ab.distance * ab.normal).stableNorm());
  // The witnesses lie on the cores (a facet is taken only if its nearest point lies on it).
  check(off_core(a, pose_a, ab.core_points[0]) <= tolerance + representable, "witness on core 1",
        off_core(a, pose_a, ab.core_points[0]));
  check(off_core(b, pose_b, ab.core_points[1]) <= tolerance + representable, "witness on core 2",
        off_core(b, pose_b, ab.core_points[1]));
  if (ab.penetrating) {
    check(ab.distance <= -radii + tolerance, "penetrating: distance <= -(R1 + R2)", ab.distance);
  } else {
    // The closest points of proximity() (not phi + (R1 + R2)^2, which cancels for a gap far
    // below the radii).
    const double gap = (proximity.core_points[1] - proximity.core_points[0]).stableNorm();
    check(std::abs(ab.distance + radii - gap) <= tolerance + representable,
          "apart: distance agrees with the proximity's closest points", ab.distance + radii - gap);
  }
}

// A shape's gradient has the shape's alternative, a row per given row and no NaN; a capsule's and
// a polygon's radius entry are finite.
bool well_formed(const diffpills::ShapeGradient& gradient, const Shape& shape) {
  if (const auto* capsule = std::get_if<diffpills::CapsuleShapeGradient>(&gradient)) {
    return std::holds_alternative<Capsule>(shape) && std::isfinite(capsule->length) &&
           std::isfinite(capsule->radius);
  }
  const auto& polygon = std::get<diffpills::PolygonShapeGradient>(gradient);
  const auto* given = std::get_if<PaddedPolygon>(&shape);
  return given != nullptr && polygon.C.rows() == given->constraint_matrix().rows() &&
         polygon.d.size() == polygon.C.rows() && !polygon.C.hasNaN() && !polygon.d.hasNaN() &&
         std::isfinite(polygon.radius);
}

bool finite(const diffpills::ShapeGradient& gradient) {
  const auto* polygon = std::get_if<diffpills::PolygonShapeGradient>(&gradient);
  return polygon == nullptr || (polygon->C.allFinite() && polygon->d.allFinite());
}

// The polygon with each row whose gradient is not finite rescaled by an exact power of two
// 2^exponents(i) to a length in [1/2, 1): the same half-planes, so the same polygon. Only those
// rows: they are active (a nonzero multiplier), so their lines pass by the polygon and d_i / |C_i|
// is within its extent, while a loose row of a short C_i would be rescaled past the accepted
// magnitudes (fuzz_proximity: d = 1e100 with |C_i| = 6e-83).
PaddedPolygon with_unit_rows(const PaddedPolygon& polygon,
                             const diffpills::PolygonShapeGradient& gradient,
                             Eigen::VectorXi& exponents) {
  Eigen::MatrixX2d C = polygon.constraint_matrix();
  Eigen::VectorXd d = polygon.constraint_offsets();
  exponents = Eigen::VectorXi::Zero(C.rows());
  for (Eigen::Index i = 0; i < C.rows(); ++i) {
    if (gradient.C.row(i).allFinite() && std::isfinite(gradient.d(i))) continue;
    int length_exponent = 0;
    std::frexp(std::hypot(C(i, 0), C(i, 1)), &length_exponent);
    exponents(i) = -length_exponent;
    C(i, 0) = std::ldexp(C(i, 0), exponents(i));
    C(i, 1) = std::ldexp(C(i, 1), exponents(i));
    d(i) = std::ldexp(d(i), exponents(i));
  }
  return PaddedPolygon(C, d, polygon.radius());
}

// `given` is `unit`, the gradient of the same polygon with its rows rescaled by 2^exponents,
// scaled back: the gradient of a row scales as 1 / |C_i|, so given = 2^exponent_i unit, which is
// +-infinity exactly where that exceeds the largest double (to rounding at the border).
bool scales_back(double given, double unit, int exponent) {
  const double expected = std::ldexp(unit, exponent);
  const double largest = std::numeric_limits<double>::max();
  if (std::isinf(given)) {
    return std::signbit(given) == std::signbit(unit) &&
           std::abs(unit) >= std::ldexp(largest * (1.0 - 1e-9), -exponent);
  }
  return std::abs(given - expected) <=
         1e-9 * std::abs(expected) + std::numeric_limits<double>::min();
}

// Shape gradients (shape_gradient.hpp): well formed, and finite except in polygon rows whose
// 1 / |C_i| carries them beyond the double range, where they are +-infinity (the command answers
// those with an error). An infinite entry is confirmed by asking again with those rows of that
// polygon rescaled to unit length: the same answer, finite, that scales back to the infinity.
template <typename Answer, typename Ask>
void check_shape_gradients(const Answer& answer, const Shape& a, const Shape& b, const Ask& ask,
                           const char* what) {
  const std::array<const Shape*, 2> shapes = {&a, &b};
  for (std::size_t side = 0; side < 2; ++side) {
    const diffpills::ShapeGradient& gradient = answer.shape_gradient[side];
    check(well_formed(gradient, *shapes[side]), what);
    if (finite(gradient)) continue;
    Eigen::VectorXi exponents;
    const PaddedPolygon unit_rows =
        with_unit_rows(std::get<PaddedPolygon>(*shapes[side]),
                       std::get<diffpills::PolygonShapeGradient>(gradient), exponents);
    const Answer again = side == 0 ? ask(unit_rows, b) : ask(a, unit_rows);
    check(again.points == answer.points, "rows rescaled to unit length: the same points");
    const auto& given = std::get<diffpills::PolygonShapeGradient>(gradient);
    const auto& unit = std::get<diffpills::PolygonShapeGradient>(again.shape_gradient[side]);
    check(finite(again.shape_gradient[side]), "rows rescaled to unit length: a finite gradient");
    for (Eigen::Index i = 0; i < given.d.size(); ++i) {
      check(scales_back(given.d(i), unit.d(i), exponents(i)) &&
                scales_back(given.C(i, 0), unit.C(i, 0), exponents(i)) &&
                scales_back(given.C(i, 1), unit.C(i, 1), exponents(i)),
            "an infinite shape gradient is the rescaled rows' beyond the double range", given.d(i));
    }
  }
}

// Two capsules in the generic case take the fused pass (src/proximity/capsule_proximity.hpp) for
// their Hessian too: phi's Hessian against the general pipeline's, each index in its unit (1 for
// a position, the scene over |q| for a quaternion component), to 1e-10 (the tests measure
// 1e-13; the free coordinates' motion may carry 1 / sin^2 <= 100).
void check_fused_hessian(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                         const diffpills::ProximityHessian& hessian, double scene) {
  const auto* capsule_a = std::get_if<Capsule>(&a);
  const auto* capsule_b = std::get_if<Capsule>(&b);
  if (capsule_a == nullptr || capsule_b == nullptr) return;
  const diffpills::ProximityHessian general =
      diffpills::detail::general_capsule_proximity_hessian(*capsule_a, pose_a, *capsule_b, pose_b);
  const auto unit = [&](int index) {
    return index % 7 < 3 ? 1.0 : scene / (index < 7 ? pose_a : pose_b).q().norm();
  };
  const double floor = 8 * std::numeric_limits<double>::denorm_min();
  for (int i = 0; i < 14; ++i) {
    for (int j = 0; j < 14; ++j) {
      const double difference = hessian.hessian(i, j) - general.hessian(i, j);
      check(std::abs(difference) <= 1e-10 * unit(i) * unit(j) + floor,
            "proximity_hessian agrees with the general pipeline", difference);
    }
  }
}

void check_second_order(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                        const diffpills::ProximityJacobian& proximity, double scene) {
  const diffpills::ProximityHessian hessian = diffpills::proximity_hessian(a, pose_a, b, pose_b);
  check(hessian.phi == proximity.phi && hessian.gradient == proximity.gradient &&
            hessian.core_points_jacobian == proximity.core_points_jacobian &&
            hessian.points_jacobian == proximity.points_jacobian,
        "proximity_hessian repeats proximity_jacobian", hessian.phi - proximity.phi);
  check_fused_hessian(a, pose_a, b, pose_b, hessian, scene);
  check(hessian.hessian.allFinite(), "Hessian of phi is finite");
  check(hessian.hessian == hessian.hessian.transpose(), "Hessian of phi is symmetric");
  const diffpills::ProximityWithHessian lean =
      diffpills::proximity_with_hessian(a, pose_a, b, pose_b);
  check(lean.phi == hessian.phi && lean.gradient == hessian.gradient &&
            lean.normal == hessian.normal && lean.points == hessian.points &&
            lean.core_points == hessian.core_points &&
            lean.cores_intersect == hessian.cores_intersect && lean.hessian == hessian.hessian,
        "proximity_with_hessian repeats proximity_hessian", lean.phi - hessian.phi);

  const diffpills::SignedDistanceJacobian first =
      diffpills::signed_distance_jacobian(a, pose_a, b, pose_b);
  const diffpills::SignedDistanceHessian second =
      diffpills::signed_distance_hessian(a, pose_a, b, pose_b);
  check(second.distance == first.distance && second.gradient == first.gradient,
        "signed_distance_hessian repeats signed_distance_jacobian",
        second.distance - first.distance);
  check(second.hessian.allFinite() && second.normal_jacobian.allFinite(),
        "Hessian of the signed distance and normal Jacobian are finite");
  check(second.hessian == second.hessian.transpose(),
        "Hessian of the signed distance is symmetric");

  const diffpills::ProximityShapeGradient shape_phi =
      diffpills::proximity_shape_gradient(a, pose_a, b, pose_b);
  check(shape_phi.phi == proximity.phi, "proximity_shape_gradient repeats phi",
        shape_phi.phi - proximity.phi);
  check_shape_gradients(
      shape_phi, a, b,
      [&](const Shape& a_again, const Shape& b_again) {
        return diffpills::proximity_shape_gradient(a_again, pose_a, b_again, pose_b);
      },
      "shape gradients of phi: one row per given row, no NaN");
  const diffpills::SignedDistanceShapeGradient shape_distance =
      diffpills::signed_distance_shape_gradient(a, pose_a, b, pose_b);
  check(shape_distance.distance == first.distance,
        "signed_distance_shape_gradient repeats distance",
        shape_distance.distance - first.distance);
  check_shape_gradients(
      shape_distance, a, b,
      [&](const Shape& a_again, const Shape& b_again) {
        return diffpills::signed_distance_shape_gradient(a_again, pose_a, b_again, pose_b);
      },
      "shape gradients of the distance: one row per given row, no NaN");
}

// Every query on one valid pair, with the invariants above.
void check_queries(FuzzedDataProvider& data, const Shape& a, const Pose& pose_a, const Shape& b,
                   const Pose& pose_b) {
  const double radii = radius_of(a) + radius_of(b);
  // The scene's size: every length of it, so that tolerances are relative.
  const double scene = std::max({size_of(a), size_of(b), radius_of(a), radius_of(b),
                                 (pose_a.r() - pose_b.r()).lpNorm<Eigen::Infinity>()});

  const diffpills::ProximityJacobian ab = diffpills::proximity_jacobian(a, pose_a, b, pose_b);
  const diffpills::ProximityJacobian ba = diffpills::proximity_jacobian(b, pose_b, a, pose_a);
  check_result(ab, radii);
  check_result(ba, radii);
  const double phi_tolerance = 1e-12 * scene * scene;
  check(std::abs(ab.phi - ba.phi) <= phi_tolerance, "swap symmetry of phi", ab.phi - ba.phi);
  // Two polygons are solved with the same one first in both orders (pair_setup.hpp,
  // solve_b_as_a), so their closest points swap to the rounding of the results even where ties
  // or the tolerances decide them (the issue asks for 1e-9 of the scene; the reviews measure
  // 1e-13).
  if (std::holds_alternative<PaddedPolygon>(a) && std::holds_alternative<PaddedPolygon>(b)) {
    check_points_swapped(ab.core_points, ba.core_points, pose_a, pose_b, scene,
                         "two polygons: both orders give the same closest points");
  }

  check_signed_distance(a, pose_a, b, pose_b, ab, radii, scene);

  const diffpills::Proximity plain = diffpills::proximity(a, pose_a, b, pose_b);
  check(plain.phi == ab.phi, "proximity and proximity_jacobian agree", plain.phi - ab.phi);

  // The interior-point reference, on one pair in four and polygons of common size: it costs
  // several times the rest, and the fuzzer's reach is its speed.
  const bool with_reference = data.ConsumeIntegralInRange<int>(0, 3) == 0;
  if (with_reference && rows_of(a) <= 48 && rows_of(b) <= 48) {
    compare_with_interior_point(a, pose_a, b, pose_b, ab.phi, radii, scene);
  }

  if (data.ConsumeBool()) check_second_order(a, pose_a, b, pose_b, ab, scene);

  const Eigen::Index rows = data.ConsumeIntegralInRange<int>(0, 3);
  diffpills::PositionArray r_a(rows, 3), r_b(rows, 3);
  diffpills::QuaternionArray q_a(rows, 4), q_b(rows, 4);
  for (Eigen::Index i = 0; i < rows; ++i) {
    r_a.row(i) = pose_a.r().transpose();
    q_a.row(i) = pose_a.q().transpose();
    r_b.row(i) = pose_b.r().transpose();
    q_b.row(i) = pose_b.q().transpose();
  }
  const int threads = data.ConsumeIntegralInRange<int>(0, 3);
  const diffpills::BatchResult batch =
      diffpills::proximity_batch(a, r_a, q_a, b, r_b, q_b, {threads});
  const bool capsules = std::holds_alternative<Capsule>(a) && std::holds_alternative<Capsule>(b);
  if (!capsules) {
    for (Eigen::Index i = 0; i < rows; ++i) {
      check(batch.phi(i) == plain.phi, "batch equals single calls", batch.phi(i) - plain.phi);
      check(batch.gradient.row(i).transpose() == plain.gradient, "batch gradient equals single");
    }
    return;
  }
  // Two capsules: the vector kernel (src/capsule_rows.hpp) agrees with the single call to 1e-12
  // of the scene (phi per length squared, gradients per length and per unit of q), for phi and
  // for the signed distance.
  const diffpills::SignedDistance single_distance =
      diffpills::signed_distance(a, pose_a, b, pose_b);
  const diffpills::SignedDistanceBatchResult distances =
      diffpills::signed_distance_batch(a, r_a, q_a, b, r_b, q_b, {threads});
  const auto agrees = [&](const Eigen::Matrix<double, 1, 14>& row,
                          const Eigen::Matrix<double, 14, 1>& single, double unit) {
    for (int j = 0; j < 14; ++j) {
      const bool quaternion = (j >= 3 && j < 7) || j >= 10;
      const double q_norm = (j < 7 ? pose_a : pose_b).q().norm();
      const double tolerance = 1e-12 * unit * (quaternion ? 2 * scene / q_norm : 1.0);
      if (!(std::abs(row(j) - single(j)) <= tolerance)) return false;
    }
    return true;
  };
  for (Eigen::Index i = 0; i < rows; ++i) {
    check(std::abs(batch.phi(i) - plain.phi) <= 4e-12 * scene * scene, "capsule batch's phi",
          batch.phi(i) - plain.phi);
    check(agrees(batch.gradient.row(i), plain.gradient, 2 * scene), "capsule batch's gradient");
    check(std::abs(distances.distance(i) - single_distance.distance) <= 2e-12 * scene,
          "capsule batch's signed distance", distances.distance(i) - single_distance.distance);
    check(agrees(distances.gradient.row(i), single_distance.gradient, 1.0),
          "capsule batch's signed-distance gradient");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  FuzzedDataProvider data(bytes, size);
  Shape a = Capsule(0, 0), b = Capsule(0, 0);
  Pose pose_a, pose_b;
  try {
    a = take_shape(data);
    b = take_shape(data);
    pose_a = take_pose(data);
    pose_b = take_pose(data);
  } catch (const std::invalid_argument&) {
    return 0;  // rejected input: the documented answer
  }
  g_inputs = "a = " + describe(a, pose_a) + "b = " + describe(b, pose_b);
  try {
    check_queries(data, a, pose_a, b, pose_b);
  } catch (const std::exception& error) {
    violated(error.what(), 0.0);  // no other exception is documented for valid shapes
  }
  return 0;
}
