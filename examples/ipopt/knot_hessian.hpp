// The Hessian of the Lagrangian of a trajectory NLP for Ipopt (problem_nlp.cpp, car_bus_ipopt.cpp):
// with variables z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}], every cost, dynamics defect and constraint
// depends on one knot's (x_k, u_k) alone (a defect x_{k+1} - f(x_k, u_k) is linear in x_{k+1}),
// so the Hessian is block diagonal by knot, each block dense ([x_k; u_k], n + m square, n at the
// last knot). Ipopt takes its lower triangle as (row, column, value) triplets.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "diffpills/trajopt/problem.hpp"

namespace diffpills::examples {

class KnotHessian {
 public:
  KnotHessian(int state_size, int control_size, int knots);

  int nonzeros() const { return first_.back(); }
  // The triplets' rows and columns, knot by knot (Ipopt's first eval_h call).
  void structure(int* rows, int* cols) const;
  // Adds knot k's block (in [x_k; u_k] order, symmetric) to values, in structure()'s order.
  void add(int k, const Eigen::MatrixXd& block, double* values) const;

 private:
  int variable(int k, int i) const;  // z's index of [x_k; u_k](i)
  int n_, m_, knots_;
  std::vector<int> first_;  // knot k's first triplet; first_[knots] = the count
};

// obj_factor * the costs' Hessian at knot k as one [x; u] block (CostExpansion's xx, uu and ux;
// xx alone at the last knot).
Eigen::MatrixXd cost_block(const trajopt::CostExpansion& cost, double objective_factor);

}  // namespace diffpills::examples
