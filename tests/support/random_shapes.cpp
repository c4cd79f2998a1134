#include "random_shapes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace diffpills::testing {
namespace {

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

}  // namespace

TestShape random_capsule(Rng& rng, double scale, double sphere_probability) {
  const bool sphere = uniform(rng, 0.0, 1.0) < sphere_probability;
  const double length = sphere ? 0.0 : uniform(rng, 0.2, 2.0) * scale;
  const double radius = uniform(rng, 0.0, 0.3) * scale;
  TestShape out{Capsule(length, radius), {}, std::max(length, radius)};
  if (sphere) {
    out.body_vertices = {Eigen::Vector3d::Zero()};
  } else {
    out.body_vertices = {Eigen::Vector3d(-0.5 * length, 0, 0), Eigen::Vector3d(0.5 * length, 0, 0)};
  }
  return out;
}

TestShape random_polygon(Rng& rng, double scale) {
  const int count = std::uniform_int_distribution<int>(3, 8)(rng);
  std::vector<double> angles;
  // Redraw until no angular gap reaches pi, so that the circle's centre is strictly inside.
  for (bool ok = false; !ok;) {
    angles.clear();
    for (int i = 0; i < count; ++i) angles.push_back(uniform(rng, 0.0, 2.0 * M_PI));
    std::sort(angles.begin(), angles.end());
    ok = true;
    for (int i = 0; i < count; ++i) {
      const double next = i + 1 < count ? angles[i + 1] : angles[0] + 2.0 * M_PI;
      ok = ok && next - angles[i] < 0.9 * M_PI && next - angles[i] > 1e-3;
    }
  }
  const double radius_of_circle = uniform(rng, 0.3, 1.0) * scale;
  const double stretch = uniform(rng, 0.4, 1.0);
  const double turn = uniform(rng, 0.0, M_PI);
  Eigen::Matrix2d map =
      Eigen::Rotation2Dd(turn).toRotationMatrix() * Eigen::Vector2d(1.0, stretch).asDiagonal();
  std::vector<Eigen::Vector2d> vertices;
  vertices.reserve(angles.size());
  for (double angle : angles) {
    vertices.emplace_back(map *
                          (radius_of_circle * Eigen::Vector2d(std::cos(angle), std::sin(angle))));
  }
  // Move a random interior point (a convex combination with weights bounded away from zero) to
  // the origin.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double total = 0.0;
  for (const auto& v : vertices) {
    const double weight = uniform(rng, 0.2, 1.0);
    centre += weight * v;
    total += weight;
  }
  centre /= total;
  for (auto& v : vertices) v -= centre;

  std::vector<Eigen::Vector2d> normals;
  std::vector<double> offsets;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d edge = vertices[(i + 1) % count] - vertices[i];
    const Eigen::Vector2d outward(edge.y(), -edge.x());
    const double row_scale = uniform(rng, 0.5, 2.0);  // rows need not be unit
    normals.emplace_back(row_scale * outward.normalized());
    offsets.push_back(normals.back().dot(vertices[i]));
  }
  const double extra = uniform(rng, 0.0, 1.0);
  if (extra < 0.25) {  // an exact duplicate, scaled
    normals.emplace_back(3.0 * normals[0]);
    offsets.push_back(3.0 * offsets[0]);
  } else if (extra < 0.5) {  // a loose row, implied by the others
    normals.push_back(normals[1]);
    offsets.push_back(offsets[1] * 1.5);
  }
  Eigen::MatrixX2d C(static_cast<Eigen::Index>(normals.size()), 2);
  Eigen::VectorXd d(static_cast<Eigen::Index>(normals.size()));
  for (std::size_t i = 0; i < normals.size(); ++i) {
    C.row(static_cast<Eigen::Index>(i)) = normals[i].transpose();
    d(static_cast<Eigen::Index>(i)) = offsets[i];
  }
  const double radius = uniform(rng, 0.0, 0.3) * scale;
  TestShape out{PaddedPolygon(C, d, radius), {}, 0.0};
  for (const auto& v : vertices) {
    out.body_vertices.emplace_back(v.x(), v.y(), 0.0);
    out.size = std::max(out.size, v.norm());
  }
  return out;
}

Pose random_pose(Rng& rng, double spread) {
  std::normal_distribution<double> normal;
  Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
  q *= uniform(rng, 0.5, 2.0) / q.norm();
  const Eigen::Vector3d r(uniform(rng, -spread, spread), uniform(rng, -spread, spread),
                          uniform(rng, -spread, spread));
  return Pose(r, q);
}

Pose rigidly_moved(const Pose& pose, const Eigen::Quaterniond& turn, const Eigen::Vector3d& shift) {
  const Eigen::Quaterniond q(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
  const Eigen::Quaterniond turned = turn * q;
  return Pose(turn * pose.r() + shift,
              Eigen::Vector4d(turned.w(), turned.x(), turned.y(), turned.z()));
}

WorldCore to_world(const TestShape& shape, const Pose& pose) {
  const Eigen::Quaternion<long double> rotation(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
  const Eigen::Matrix<long double, 3, 3> R = rotation.normalized().toRotationMatrix();
  WorldCore core;
  for (const auto& v : shape.body_vertices) {
    core.vertices.emplace_back(pose.r().cast<long double>() + R * v.cast<long double>());
  }
  return core;
}

}  // namespace diffpills::testing
