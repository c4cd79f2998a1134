#include "knot_hessian.hpp"

#include <algorithm>

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

// The triplets: within a block, the entries (i, j) with j <= i; the controls come after every
// state in z, so variable(k, i) >= variable(k, j) there and each triplet is in the lower triangle.
bool KnotHessian::eval_h(const trajopt::Problem& problem, const double* z, double objective_factor,
                         const double* multipliers, const ConstraintHessian& constraints, int* rows,
                         int* cols, double* values) const {
  if (values != nullptr)
    return evaluate(problem, z, objective_factor, multipliers, constraints, values);
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
  return true;
}

namespace {

// objective_factor * the costs' Hessian as one [x; u] block (xx alone at the last knot).
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

}  // namespace

bool KnotHessian::evaluate(const trajopt::Problem& problem, const double* z,
                           double objective_factor, const double* multipliers,
                           const ConstraintHessian& constraints, double* values) const {
  std::fill(values, values + nonzeros(), 0.0);
  for (int k = 0; k < knots_; ++k) {
    const bool last = k + 1 == knots_;
    const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(z + variable(k, 0), n_);
    const Eigen::VectorXd u =
        last ? Eigen::VectorXd()
             : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(z + variable(k, n_), m_));
    Eigen::MatrixXd block =
        cost_block(last ? problem.terminal_cost(x) : problem.stage_cost(k, x, u), objective_factor);
    if (!last) {
      const Eigen::Map<const Eigen::VectorXd> defect(multipliers + std::ptrdiff_t{n_} * k, n_);
      block += problem.dynamics_hessian(x, u, -defect);
    }
    block += constraints(k, x, u);
    const Eigen::Index size = n_ + u.size();
    if (block.rows() != size || block.cols() != size) return false;
    int entry = first_[static_cast<std::size_t>(k)];
    for (Eigen::Index i = 0; i < size; ++i) {
      for (Eigen::Index j = 0; j <= i; ++j) values[entry++] = block(i, j);
    }
  }
  return true;
}

}  // namespace diffpills::examples
