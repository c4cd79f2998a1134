#include "knot_hessian.hpp"

namespace diffpills::examples {

KnotHessian::KnotHessian(int state_size, int control_size, int knots)
    : n_(state_size), m_(control_size), knots_(knots), first_{0} {
  for (int k = 0; k < knots_; ++k) {
    const int size = n_ + (k + 1 < knots_ ? m_ : 0);
    first_.push_back(first_.back() + size * (size + 1) / 2);
  }
}

int KnotHessian::variable(int k, int i) const {
  return i < n_ ? n_ * k + i : n_ * knots_ + m_ * k + (i - n_);
}

// Within a block, the entries (i, j) with j <= i; the controls come after every state in z, so
// variable(k, i) >= variable(k, j) there and each triplet is in the lower triangle.
void KnotHessian::structure(int* rows, int* cols) const {
  int entry = 0;
  for (int k = 0; k < knots_; ++k) {
    const int size = n_ + (k + 1 < knots_ ? m_ : 0);
    for (int i = 0; i < size; ++i) {
      for (int j = 0; j <= i; ++j) {
        rows[entry] = variable(k, i);
        cols[entry] = variable(k, j);
        ++entry;
      }
    }
  }
}

void KnotHessian::add(int k, const Eigen::MatrixXd& block, double* values) const {
  int entry = first_[static_cast<std::size_t>(k)];
  for (Eigen::Index i = 0; i < block.rows(); ++i) {
    for (Eigen::Index j = 0; j <= i; ++j) values[entry++] += block(i, j);
  }
}

Eigen::MatrixXd cost_block(const trajopt::CostExpansion& cost, double objective_factor) {
  const Eigen::Index n = cost.xx.rows(), m = cost.uu.rows();
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(n + m, n + m);
  block.topLeftCorner(n, n) = cost.xx;
  if (m > 0) {
    block.bottomRightCorner(m, m) = cost.uu;
    block.bottomLeftCorner(m, n) = cost.ux;
    block.topRightCorner(n, m) = cost.ux.transpose();
  }
  return objective_factor * block;
}

}  // namespace diffpills::examples
