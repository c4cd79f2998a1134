// phi and the closest points against the brute-force reference (support/reference.hpp) on
// random pairs of every ordering at scales 1e-3, 1 and 1e3, and capsule pairs against FCL.
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/distance.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>

#include "diffpills/diffpills.hpp"
#include "support/fcl_pose.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"

namespace diffpills::testing {
namespace {

double radius_of(const Shape& shape) {
  return std::visit([](const auto& s) { return s.radius(); }, shape);
}

// Does p lie on the core of `shape` at `pose`, to within tolerance? Checked in the body frame
// (through Eigen's quaternion) against the test's own vertex list.
bool on_core(const TestShape& shape, const Pose& pose, const Eigen::Vector3d& p, double tolerance) {
  const Eigen::Quaterniond rotation(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
  const Eigen::Vector3d body = rotation.normalized().conjugate() * (p - pose.r());
  const auto& v = shape.body_vertices;
  if (v.size() <= 2) {
    const double half = v.size() == 1 ? 0.0 : v[1].x();
    return std::abs(body.y()) <= tolerance && std::abs(body.z()) <= tolerance &&
           std::abs(body.x()) <= half + tolerance;
  }
  if (std::abs(body.z()) > tolerance) return false;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector3d edge = v[(i + 1) % v.size()] - v[i];
    if (edge.cross(body - v[i]).z() < -tolerance * edge.norm()) return false;
  }
  return true;
}

struct ErrorTally {
  double phi = 0.0;       // max |phi - phi_ref| / max(scale^2, |phi_ref|)
  double distance = 0.0;  // max ||p1 - p2| - d_ref| / scale
  int pairs = 0;
};

void check_against_reference(const TestShape& a, const Pose& pose_a, const TestShape& b,
                             const Pose& pose_b, double scale, const ProximityOptions& options,
                             ErrorTally& tally) {
  const ClosestPair reference = brute_force_closest(to_world(a, pose_a), to_world(b, pose_b));
  const Proximity result = proximity(a.shape, pose_a, b.shape, pose_b, options);
  const double radius_sum = radius_of(a.shape) + radius_of(b.shape);
  const long double reference_phi =
      reference.distance * reference.distance - static_cast<long double>(radius_sum) * radius_sum;
  const double phi_error =
      std::abs(static_cast<double>(result.phi - reference_phi)) /
      std::max<double>(scale * scale, std::abs(static_cast<double>(reference_phi)));
  const double distance = (result.core_points[0] - result.core_points[1]).norm();
  const double distance_error =
      std::abs(distance - static_cast<double>(reference.distance)) / scale;
  tally.phi = std::max(tally.phi, phi_error);
  tally.distance = std::max(tally.distance, distance_error);
  ++tally.pairs;
  ASSERT_LE(phi_error, 1e-9) << "phi " << result.phi << " reference "
                             << static_cast<double>(reference_phi);
  ASSERT_LE(distance_error, 1e-9);
  ASSERT_TRUE(on_core(a, pose_a, result.core_points[0], 1e-9 * scale));
  ASSERT_TRUE(on_core(b, pose_b, result.core_points[1], 1e-9 * scale));
  ASSERT_NEAR(result.normal.norm(), 1.0, 1e-12);
  ASSERT_LE(
      (result.points[0] - (result.core_points[0] + radius_of(a.shape) * result.normal)).norm(),
      1e-12 * (scale + result.core_points[0].norm()));
  ASSERT_LE(
      (result.points[1] - (result.core_points[1] - radius_of(b.shape) * result.normal)).norm(),
      1e-12 * (scale + result.core_points[1].norm()));
  if (!result.cores_intersect) {
    ASSERT_LE((result.normal - (result.core_points[1] - result.core_points[0]) / distance).norm(),
              1e-9);
  }
  ASSERT_TRUE(result.gradient.allFinite());
}

TestShape random_shape(Rng& rng, bool polygon, double scale) {
  return polygon ? random_polygon(rng, scale) : random_capsule(rng, scale, 0.05);
}

void run_random_pairs(const ProximityOptions& options, int per_ordering_and_scale,
                      std::uint64_t seed, const char* label) {
  Rng rng(seed);
  for (double scale : {1e-3, 1.0, 1e3}) {
    for (int ordering = 0; ordering < 4; ++ordering) {
      ErrorTally tally;
      for (int i = 0; i < per_ordering_and_scale; ++i) {
        const TestShape a = random_shape(rng, ordering & 2, scale);
        const TestShape b = random_shape(rng, ordering & 1, scale);
        const Pose pose_a = random_pose(rng, 1.2 * scale);
        const Pose pose_b = random_pose(rng, 1.2 * scale);
        check_against_reference(a, pose_a, b, pose_b, scale, options, tally);
        if (::testing::Test::HasFatalFailure()) {
          ADD_FAILURE() << label << " ordering " << ordering << " scale " << scale << " pair " << i;
          return;
        }
      }
      std::cout << "[reference] " << label << " " << ((ordering & 2) ? "polygon" : "capsule") << "-"
                << ((ordering & 1) ? "polygon" : "capsule") << " scale " << scale << ": "
                << tally.pairs << " pairs, max relative phi error " << tally.phi
                << ", max distance error / scale " << tally.distance << "\n";
    }
  }
}

TEST(ProximityReference, DefaultMethodAgreesWithBruteForceOnTenThousandPairs) {
  run_random_pairs({Method::kDefault}, 900, 20261121, "default");  // 4 x 3 x 900 = 10,800
}

TEST(ProximityReference, InteriorPointMethodAgreesWithBruteForce) {
  run_random_pairs({Method::kInteriorPoint}, 300, 7, "interior_point");
}

TEST(ProximityReference, CapsulePairsAgreeWithFcl) {
  Rng rng(99);
  double worst = 0.0;
  int compared = 0;
  for (double scale : {1e-3, 1.0, 1e3}) {
    for (int i = 0; i < 2000; ++i) {
      const TestShape a = random_capsule(rng, scale);
      const TestShape b = random_capsule(rng, scale);
      const Pose pose_a = random_pose(rng, 1.5 * scale);
      const Pose pose_b = random_pose(rng, 1.5 * scale);
      const auto& ca = std::get<Capsule>(a.shape);
      const auto& cb = std::get<Capsule>(b.shape);
      const Proximity ours = proximity(ca, pose_a, cb, pose_b);
      const double core_distance = (ours.core_points[0] - ours.core_points[1]).norm();
      if (core_distance <= ca.radius() + cb.radius() + 1e-6 * scale) {
        continue;  // FCL reports no signed distance for touching capsules
      }
      fcl::Capsuled fa(ca.radius(), ca.length());
      fcl::Capsuled fb(cb.radius(), cb.length());
      fcl::DistanceRequestd request;
      fcl::DistanceResultd result;
      fcl::distance(&fa, fcl_capsule_transform(pose_a), &fb, fcl_capsule_transform(pose_b), request,
                    result);
      const double fcl_core_distance = result.min_distance + ca.radius() + cb.radius();
      const double error = std::abs(fcl_core_distance - core_distance) / scale;
      worst = std::max(worst, error);
      ++compared;
      ASSERT_LE(error, 1e-9) << "ours " << core_distance << " fcl " << fcl_core_distance;
    }
  }
  std::cout << "[fcl] " << compared << " separated capsule pairs, max |distance - FCL| / scale "
            << worst << "\n";
  EXPECT_GT(compared, 3000);
}

}  // namespace
}  // namespace diffpills::testing
