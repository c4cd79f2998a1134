#include "demo_scene.hpp"

#include <cmath>
#include <iomanip>
#include <ostream>

#include "diffpills/diffpills.hpp"

namespace diffpills::app {
namespace {

void print_vector(std::ostream& out, const char* label, const Eigen::VectorXd& v) {
  out << "  " << std::left << std::setw(22) << label << std::right << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    out << (i ? ", " : "") << std::setw(9) << std::fixed << std::setprecision(5) << v(i);
  }
  out << " ]\n";
}

}  // namespace

Fig1Scene fig1_scene() {
  Eigen::MatrixX2d C(6, 2);
  Eigen::VectorXd d(6);
  for (int i = 0; i < 6; ++i) {
    const double angle = M_PI / 3.0 * i;
    C.row(i) << std::cos(angle), std::sin(angle);
    d(i) = 0.6;
  }
  return {Capsule(1.2, 0.2), Pose({0.4, 0.3, 0.9}, {std::cos(0.35), 0.0, std::sin(0.35), 0.0}),
          PaddedPolygon(C, d, 0.1),
          Pose({0.0, 0.0, 0.0}, {std::cos(0.2), std::sin(0.2), 0.0, 0.0})};
}

int run_scene_demo(std::ostream& out) {
  const Fig1Scene scene = fig1_scene();
  const Capsule& capsule = scene.capsule;
  const Pose& capsule_pose = scene.capsule_pose;
  const PaddedPolygon& polygon = scene.polygon;
  const Pose& polygon_pose = scene.polygon_pose;
  const ProximityJacobian result = proximity_jacobian(capsule, capsule_pose, polygon, polygon_pose);
  out << "diffpills " << kVersion << " -- the paper's Fig. 1 scene\n"
      << "  shape 1: capsule, length 1.2, radius 0.2, r = [0.4, 0.3, 0.9]\n"
      << "  shape 2: padded regular hexagon, apothem 0.6, radius 0.1, r = [0, 0, 0]\n\n";
  out << "  phi = |p1 - p2|^2 - (R1 + R2)^2 = " << std::setprecision(6) << result.phi
      << (result.phi > 0 ? "  (apart)\n" : "  (in contact)\n");
  print_vector(out, "core point p1", result.core_points[0]);
  print_vector(out, "core point p2", result.core_points[1]);
  print_vector(out, "surface point p~1", result.points[0]);
  print_vector(out, "surface point p~2", result.points[1]);
  print_vector(out, "normal (1 -> 2)", result.normal);
  print_vector(out, "dphi/dr1", result.gradient.segment<3>(0));
  print_vector(out, "dphi/dq1", result.gradient.segment<4>(3));
  print_vector(out, "dphi/dr2", result.gradient.segment<3>(7));
  print_vector(out, "dphi/dq2", result.gradient.segment<4>(10));
  print_vector(out, "dphi/dtheta1 (body)",
               attitude_gradient(capsule_pose.q(), result.gradient.segment<4>(3)));
  return 0;
}

}  // namespace diffpills::app
