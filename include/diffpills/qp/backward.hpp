// Differentiation through the QP solved by InteriorPointSolver (paper section II-C).
//
// For a scalar loss l(x*) of the solution, backward() turns dl/dx into the gradients of l with
// respect to every problem datum by the implicit function theorem on the KKT conditions
// (kkt:1)-(kkt:2), in the vector-Jacobian form of OptNet (eqs. optnet_P to optnet):
//
//   [d_x; d_lambda] = -[ P  G'D(lambda) ; G  D(Gx - h) ]^-1 [ dl/dx ; 0 ]
//   dl/dP = 1/2 (d_x x' + x d_x')          (the paper prints "lambda d_x'": a typo for x d_x')
//   dl/dc = d_x
//   dl/dG = D(lambda) d_lambda x' + lambda d_x'
//   dl/dh = -D(lambda) d_lambda
//
// With Gx - h = -s, the first block row is P a + G'D(lambda) b = dl/dx and the second
// G a - D(s) b = 0, so b = D(1/s) G a and (P + G'WG) a = dl/dx with W = D(lambda / s): the very
// matrix the solver factored. backward() reuses that Cholesky factorization; no new one is made.
// Near the solution W is huge on active rows and tiny on inactive ones, so the result matches
// the exact active-set derivative to about 1e-9 relative on well-conditioned problems, 1e-6 at
// worst in the tests (see InteriorPointSolver::factorization for the point it is taken at).
// Callers needing exact derivatives of a polished solution can solve the active-set KKT system;
// the proximity Jacobians do that.
#pragma once

#include <Eigen/Core>

#include "diffpills/qp/interior_point.hpp"

namespace diffpills::qp {

struct QpGradient {
  Eigen::MatrixXd P;  // dl/dP, symmetric
  Eigen::VectorXd c;  // dl/dc
  Eigen::MatrixXd G;  // dl/dG
  Eigen::VectorXd h;  // dl/dh
};

// Throws std::logic_error unless the solver's last solve() returned Status::kSolved, and
// std::invalid_argument if dl_dx does not have n entries.
QpGradient backward(const InteriorPointSolver& solver, const Eigen::VectorXd& dl_dx);

}  // namespace diffpills::qp
