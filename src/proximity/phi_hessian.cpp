#include "phi_hessian.hpp"

namespace diffpills::detail {
namespace {

constexpr int kR1 = 0, kQ1 = 3, kR2 = 7, kQ2 = 10;  // the column blocks of x = [r1 q1 r2 q2]

// The lower triangle of J'J for J = [I, G1, -I, -G2], block by block: every block is I or a
// product of the G's. The upper blocks off the diagonal are left unset (mirrored at the end).
void set_lower_gauss_newton(const std::array<Eigen::Matrix<double, 3, 4>, 2>& turn,
                            Eigen::Matrix<double, 14, 14>& H) {
  const Eigen::Matrix<double, 3, 4>& G1 = turn[0];
  const Eigen::Matrix<double, 3, 4>& G2 = turn[1];
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  H.block<3, 3>(kR1, kR1) = I;
  H.block<4, 3>(kQ1, kR1) = G1.transpose();
  H.block<4, 4>(kQ1, kQ1).noalias() = G1.transpose() * G1;
  H.block<3, 3>(kR2, kR1) = -I;
  H.block<3, 4>(kR2, kQ1) = -G1;
  H.block<3, 3>(kR2, kR2) = I;
  H.block<4, 3>(kQ2, kR1) = -G2.transpose();
  H.block<4, 4>(kQ2, kQ1).noalias() = -G2.transpose() * G1;
  H.block<4, 3>(kQ2, kR2) = G2.transpose();
  H.block<4, 4>(kQ2, kQ2).noalias() = G2.transpose() * G2;
}

// The reduced term coupling' free_motion at the fixed size Z (so that the sums unroll), in the
// lower triangle only: the upper one is mirrored from it at the end.
template <int Z>
void add_reduced_term(const PointMotion& motion, Eigen::Matrix<double, 14, 14>& H) {
  for (int j = 0; j < 14; ++j) {
    for (int i = j; i < 14; ++i) {
      double sum = 0.0;
      for (int k = 0; k < Z; ++k) sum += motion.coupling(k, i) * motion.free_motion(k, j);
      H(i, j) += sum;
    }
  }
}

}  // namespace

void phi_hessian(double scale, const PosedCore& a, const ClosestFeature& side_a, const PosedCore& b,
                 const ClosestFeature& side_b, const PointMotion& motion,
                 Eigen::Matrix<double, 14, 14>& H) {
  const Eigen::Vector3d e = a.r + a.attitude.matrix() * side_a.body_point -
                            (b.r + b.attitude.matrix() * side_b.body_point);
  set_lower_gauss_newton(motion.turn, H);
  switch (motion.free) {
    case 1:
      add_reduced_term<1>(motion, H);
      break;
    case 2:
      add_reduced_term<2>(motion, H);
      break;
    case 3:
      add_reduced_term<3>(motion, H);
      break;
    case 4:
      add_reduced_term<4>(motion, H);
      break;
    default:  // both points fixed: no reduced term
      break;
  }
  // The factor 2 of f = |e|^2 and the units, applied to the lower triangle as it is mirrored:
  // quaternion rows and columns times the scale (the q-q block twice, one product each).
  const double two_scale = 2.0 * scale;
  const double row_factors[14] = {2.0, 2.0, 2.0, two_scale, two_scale, two_scale, two_scale,
                                  2.0, 2.0, 2.0, two_scale, two_scale, two_scale, two_scale};
  for (int j = 0; j < 14; ++j) {
    const double column_factor = (j >= kQ1 && j < kR2) || j >= kQ2 ? scale : 1.0;
    for (int i = j; i < 14; ++i) H(j, i) = H(i, j) = H(i, j) * row_factors[i] * column_factor;
  }
  // The rotations' own second derivatives, 2 d^2/dq^2 (e . Q(q) xi) per side, with the units
  // folded in by rotate_hessian (times scale^2 before its 1 / |q|^2, which alone can underflow).
  H.block<4, 4>(kQ1, kQ1) += 2.0 * a.attitude.rotate_hessian(side_a.body_point, e, scale);
  H.block<4, 4>(kQ2, kQ2) -= 2.0 * b.attitude.rotate_hessian(side_b.body_point, e, scale);
}

}  // namespace diffpills::detail
