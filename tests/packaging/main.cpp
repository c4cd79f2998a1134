// Uses the installed library exactly as DESIGN.md section 2 shows, and checks one analytic answer.
#include <cmath>
#include <diffpills/diffpills.hpp>
#include <iostream>

int main() {
  const diffpills::Capsule cap{2.0, 0.2};
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  Eigen::VectorXd d = Eigen::VectorXd::Ones(4);
  const diffpills::PaddedPolygon poly{C, d, 0.1};
  const diffpills::Pose pose1{Eigen::Vector3d(0, 0, 2), Eigen::Vector4d(1, 0, 0, 0)};
  const diffpills::Pose pose2{Eigen::Vector3d(0, 0, 0), Eigen::Vector4d(1, 0, 0, 0)};
  const diffpills::Proximity res = diffpills::proximity(cap, pose1, poly, pose2);
  // The capsule lies flat 2 above the square: phi = 2^2 - 0.3^2.
  const bool ok = std::abs(res.phi - (4.0 - 0.09)) < 1e-12 && res.gradient.size() == 14;
  std::cout << "diffpills " << diffpills::kVersion << " downstream: phi = " << res.phi
            << (ok ? " (ok)" : " (WRONG)") << "\n";
  return ok ? 0 : 1;
}
