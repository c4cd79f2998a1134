#include "measure_hessian.hpp"

#include "unit_quaternion.hpp"

namespace diffpills::detail {

// J_f = [I, D_1, -I, -D_2] with D_i = d(Q(q_i) xi_i)/dq_i (3 x 4): its blocks are applied one by
// one (J_f' dw is dw, D_1' dw, -dw, -D_2' dw by rows) rather than as a 3 x 14 matrix with zeros.
Eigen::Matrix<double, 14, 14> measure_hessian(const Pose& pose_a, const Pose& pose_b,
                                              const std::array<Eigen::Vector3d, 2>& points,
                                              const Eigen::Matrix<double, 6, 14>& points_jacobian,
                                              const Eigen::Vector3d& w,
                                              const Eigen::Matrix<double, 3, 14>& dw) {
  const std::array<const Pose*, 2> poses = {&pose_a, &pose_b};
  Eigen::Matrix<double, 14, 14> H;
  for (Eigen::Index side = 0; side < 2; ++side) {
    const auto index = static_cast<std::size_t>(side);
    const double sign = side == 0 ? 1.0 : -1.0;
    const UnitQuaternion attitude(poses[index]->q());
    const Eigen::Matrix3d& rotation = attitude.matrix();
    const Eigen::Vector3d xi = rotation.transpose() * (points[index] - poses[index]->r());
    const Eigen::Matrix<double, 3, 4> rotate = attitude.rotate_jacobian(xi);
    // dxi/dx = Q' (J_i - J_f,i), J_f,i = [I, D_i] in this side's columns.
    Eigen::Matrix<double, 3, 14> moved = points_jacobian.middleRows<3>(3 * side);
    moved.middleCols<3>(7 * side) -= Eigen::Matrix3d::Identity();
    moved.middleCols<4>(7 * side + 3) -= rotate;
    const Eigen::Matrix<double, 3, 14> xi_jacobian = rotation.transpose() * moved;
    const Eigen::Index r = 7 * side, q = 7 * side + 3;
    H.middleRows<3>(r) = sign * dw;
    H.middleRows<4>(q) = sign * (rotate.transpose() * dw +
                                 attitude.rotate_transpose_jacobian(w).transpose() * xi_jacobian);
    H.block<4, 4>(q, q) += sign * attitude.rotate_hessian(xi, w);
  }
  return 0.5 * (H + H.transpose());
}

}  // namespace diffpills::detail
