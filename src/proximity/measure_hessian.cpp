#include "measure_hessian.hpp"

#include "diffpills/rotation.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {

Eigen::Matrix<double, 14, 14> measure_hessian(const Pose& pose_a, const Pose& pose_b,
                                              const std::array<Eigen::Vector3d, 2>& points,
                                              const Eigen::Matrix<double, 6, 14>& points_jacobian,
                                              const Eigen::Vector3d& w,
                                              const Eigen::Matrix<double, 3, 14>& dw) {
  const std::array<const Pose*, 2> poses = {&pose_a, &pose_b};
  const std::array<UnitQuaternion, 2> attitudes = {UnitQuaternion(pose_a.q()),
                                                   UnitQuaternion(pose_b.q())};
  Eigen::Matrix<double, 3, 14> fixed_difference = Eigen::Matrix<double, 3, 14>::Zero();
  std::array<Eigen::Matrix<double, 3, 14>, 2> xi_jacobian;
  std::array<Eigen::Vector3d, 2> xi;
  for (int side = 0; side < 2; ++side) {
    const auto index = static_cast<std::size_t>(side);
    const Eigen::Matrix3d& rotation = attitudes[index].matrix();
    xi[index] = rotation.transpose() * (points[index] - poses[index]->r());
    Eigen::Matrix<double, 3, 14> fixed = Eigen::Matrix<double, 3, 14>::Zero();
    fixed.block<3, 3>(0, 7 * side) = Eigen::Matrix3d::Identity();
    fixed.block<3, 4>(0, 7 * side + 3) = attitudes[index].rotate_jacobian(xi[index]);
    xi_jacobian[index] = rotation.transpose() * (points_jacobian.middleRows<3>(3 * side) - fixed);
    fixed_difference += side == 0 ? fixed : Eigen::Matrix<double, 3, 14>(-fixed);
  }
  Eigen::Matrix<double, 14, 14> H = fixed_difference.transpose() * dw;
  for (int side = 0; side < 2; ++side) {
    const auto index = static_cast<std::size_t>(side);
    const double sign = side == 0 ? 1.0 : -1.0;
    const int q = 7 * side + 3;
    H.block<4, 4>(q, q) += sign * rotate_hessian(poses[index]->q(), xi[index], w);
    H.middleRows<4>(q) +=
        sign * attitudes[index].rotate_transpose_jacobian(w).transpose() * xi_jacobian[index];
  }
  return 0.5 * (H + H.transpose());
}

}  // namespace diffpills::detail
