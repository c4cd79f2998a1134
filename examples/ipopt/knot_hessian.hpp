// The Hessian of the Lagrangian of a trajectory NLP for Ipopt (problem_nlp.cpp, car_bus_ipopt.cpp):
// with variables z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}], every cost, dynamics defect and constraint
// depends on one knot's (x_k, u_k) alone (a defect x_{k+1} - f(x_k, u_k) is linear in x_{k+1}),
// so the Hessian is block diagonal by knot, each block dense ([x_k; u_k], n + m square, n at the
// last knot). Ipopt takes its lower triangle as (row, column, value) triplets.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "diffpills/trajopt/problem.hpp"

namespace diffpills::examples {

class KnotHessian {
 public:
  KnotHessian(int state_size, int control_size, int knots);

  int nonzeros() const { return first_.back(); }

  // knot k's constraints' part of its block: the Hessian of mu_k' c_k(x, u) with the NLP's own
  // rows and multipliers ([x; u] square, x alone at the last knot).
  using ConstraintHessian =
      std::function<Eigen::MatrixXd(int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u)>;
  // Ipopt's eval_h. Without values (its first call), the triplets' rows and columns, knot by
  // knot. With values, the Lagrangian's Hessian at z in that order: per knot, objective_factor
  // times the costs' Hessian (CostExpansion's xx, uu, ux), the defect x_{k+1} - f(x_k, u_k)
  // weighted by its multipliers (multipliers[n k .. n k + n), none at the last knot: the Hessian
  // of -lambda' f) and the constraints' part. False, for Ipopt an evaluation error, if a block
  // has another size than the knot's (it would be scattered past the triplets).
  bool eval_h(const trajopt::Problem& problem, const double* z, double objective_factor,
              const double* multipliers, const ConstraintHessian& constraints, int* rows, int* cols,
              double* values) const;

 private:
  bool evaluate(const trajopt::Problem& problem, const double* z, double objective_factor,
                const double* multipliers, const ConstraintHessian& constraints,
                double* values) const;
  int variable(int k, int i) const;  // z's index of [x_k; u_k](i)
  int n_, m_, knots_;
  std::vector<int> first_;  // knot k's first triplet; first_[knots] = the count
};

}  // namespace diffpills::examples
