// A discrete-time trajectory optimization problem for diffpills::trajopt:
//
//   minimize    sum_{k<N-1} l_k(x_k, u_k) + l_N(x_{N-1})
//   subject to  x_{k+1} = f(x_k, u_k),  x_0 given,
//               c_k(x_k, u_k) <= 0 and e_k(x_k, u_k) = 0 at every knot (u absent at the last)
//
// with N knots, states x in R^n and controls u in R^m. A problem supplies its dynamics, costs and
// constraints with their first derivatives (and the costs' second derivatives); the solver never
// differentiates numerically. A problem may also supply the second derivatives of its dynamics and
// constraints, for solvers that use the exact Hessian of the Lagrangian (the examples' Ipopt
// cross-check); ALTRO does not use them. Implementations must be pure: the same inputs give the
// same outputs.
#pragma once

#include <Eigen/Core>

namespace diffpills::trajopt {

// Value and derivatives of one knot's constraints: rows [0, equalities) are equalities e = 0,
// the rest inequalities c <= 0. At the last knot du has zero columns.
struct KnotConstraints {
  Eigen::VectorXd value;
  Eigen::MatrixXd dx;
  Eigen::MatrixXd du;
  int equalities = 0;
};

// A cost term's value with its gradient and Hessian (Gauss-Newton or exact).
struct CostExpansion {
  double value = 0.0;
  Eigen::VectorXd x, u;    // gradients
  Eigen::MatrixXd xx, uu;  // Hessians
  Eigen::MatrixXd ux;      // mixed, m x n
};

class Problem {
 public:
  virtual ~Problem() = default;

  virtual int state_size() const = 0;
  virtual int control_size() const = 0;
  virtual int knots() const = 0;  // N: states x_0..x_{N-1}, controls u_0..u_{N-2}

  // next = f(x, u) with A = df/dx (n x n), B = df/du (n x m).
  virtual void dynamics(const Eigen::VectorXd& x, const Eigen::VectorXd& u, Eigen::VectorXd& next,
                        Eigen::MatrixXd& A, Eigen::MatrixXd& B) const = 0;

  // l_k(x, u) for k < N - 1 and l_N(x) for the last knot (expansion.u and friends unused there).
  virtual CostExpansion stage_cost(int k, const Eigen::VectorXd& x,
                                   const Eigen::VectorXd& u) const = 0;
  virtual CostExpansion terminal_cost(const Eigen::VectorXd& x) const = 0;

  // Constraints at knot k (k = N - 1: terminal, u empty). The row count of a knot must not change
  // between calls. The default has none.
  virtual KnotConstraints constraints(int k, const Eigen::VectorXd& x,
                                      const Eigen::VectorXd& u) const;

  // Values only, for the line search and the multiplier updates, which need no derivatives.
  // The defaults call the full evaluations; a problem overrides them when that saves work
  // (measured on the car-bus problem: the line search's derivative evaluations were a fifth of
  // the solve).
  virtual double stage_cost_value(int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u) const {
    return stage_cost(k, x, u).value;
  }
  virtual double terminal_cost_value(const Eigen::VectorXd& x) const {
    return terminal_cost(x).value;
  }
  // value and equalities filled; dx and du may be left empty.
  virtual KnotConstraints constraint_values(int k, const Eigen::VectorXd& x,
                                            const Eigen::VectorXd& u) const {
    return constraints(k, x, u);
  }

  // Second derivatives. A problem that returns true here implements the two functions below, and
  // its CostExpansion Hessians are exact (not Gauss-Newton); the defaults have none and throw
  // std::logic_error.
  virtual bool has_second_derivatives() const { return false; }
  // The Hessian of lambda' f(x, u) with respect to [x; u], (n + m) x (n + m), for lambda in R^n.
  // Both throw std::invalid_argument for vectors of the wrong size (require_size below).
  virtual Eigen::MatrixXd dynamics_hessian(const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                                           const Eigen::VectorXd& lambda) const;
  // The Hessian of mu' [e_k; c_k](x, u) with respect to [x; u] (x alone at the last knot), for one
  // multiplier per row of constraints(k, x, u).
  virtual Eigen::MatrixXd constraint_hessian(int k, const Eigen::VectorXd& x,
                                             const Eigen::VectorXd& u,
                                             const Eigen::VectorXd& mu) const;
};

// Throws std::invalid_argument("<name>: expected <size> entries, got <v.size()>") unless v has size
// entries: for the second-derivative functions, whose fixed-size models would otherwise read past
// a short vector.
void require_size(const Eigen::VectorXd& v, Eigen::Index size, const char* name);

}  // namespace diffpills::trajopt
