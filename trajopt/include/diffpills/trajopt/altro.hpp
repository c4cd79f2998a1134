// An ALTRO-style solver (Howell, Jackson, Manchester 2019): an augmented Lagrangian outer loop
// around iLQR, with Altro.jl's defaults.
//
// Outer loop: the constraints enter the cost as lambda'c + 1/2 c' I_mu c, with I_mu = mu on
// equalities and on inequalities that are violated or have lambda > 0, zero otherwise. After each
// inner solve lambda <- max(0, lambda + mu c) (inequalities; equalities without the max), and
// mu <- min(10 mu, 1e8), until the largest violation is below constraint_tolerance.
// Inner loop: iLQR on that cost. The backward pass regularizes Quu + rho I, with rho grown by 1.6
// on a failed factorization or line search and kept in [1e-8, 1e8]; the forward pass backtracks
// from a full step and accepts when actual / expected decrease lies in [1e-8, 10].
// Projected-Newton polish (ALTRO's last stage): once the augmented Lagrangian has converged, the
// active constraints (the initial state, the dynamics, equalities, inequalities with a multiplier
// or a violation) are driven to zero by Gauss-Newton projections of all states and controls,
// dz = -D'(D D')^-1 c, each accepted only if it lowers the largest violation. The states then
// satisfy the dynamics to the polish tolerance instead of exactly, as a rollout would.
// Every loop has a cap; the result says how it ended.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "diffpills/trajopt/problem.hpp"

namespace diffpills::trajopt {

struct AltroSettings {
  int max_outer_iterations = 30;
  int max_inner_iterations = 200;  // per outer iteration
  int max_total_iterations = 1000;
  double constraint_tolerance = 1e-6;
  double cost_tolerance = 1e-8;      // inner convergence: relative decrease of the AL cost
  double gradient_tolerance = 1e-6;  // inner convergence: largest feedforward step, relative
  double penalty_initial = 1.0;
  double penalty_scaling = 10.0;
  double penalty_max = 1e8;
  double regularization_initial = 1e-8;
  double regularization_min = 1e-8;
  double regularization_max = 1e8;
  double regularization_growth = 1.6;
  double line_search_lower = 1e-8;
  double line_search_upper = 10.0;
  int line_search_steps = 20;
  bool polish = true;
  int polish_iterations = 10;
  double polish_tolerance = 1e-10;  // largest violation, dynamics defects included
};

enum class AltroStatus {
  kSolved,                 // max violation <= constraint_tolerance and the inner loop converged
  kMaxIterations,          // an iteration cap was reached first
  kRegularizationFailure,  // rho exceeded regularization_max
  kNonFinite,  // NaN or infinity from the problem reached the accepted trajectory's cost, states
               // or constraint values, or the backward pass's Q terms or gains (one met only in a
               // line-search trial is rejected like any bad step)
};

const char* to_string(AltroStatus status);

struct AltroResult {
  std::vector<Eigen::VectorXd> states;    // N
  std::vector<Eigen::VectorXd> controls;  // N - 1
  AltroStatus status = AltroStatus::kMaxIterations;
  double cost = 0.0;           // the problem's cost, without constraint terms
  double max_violation = 0.0;  // largest equality |e|, positive inequality c or dynamics defect
  int iterations = 0;          // iLQR iterations, over all outer iterations
  int outer_iterations = 0;
  int polish_iterations = 0;  // accepted projected-Newton steps
};

// Solves from x0 with the controls as the initial guess (N - 1 of them; the states follow by
// rollout). Throws std::invalid_argument on sizes that do not match the problem, a non-finite x0
// or control, fewer than 2 knots, settings out of range (detail::check_settings), and constraints
// whose rows break problem.hpp's rules. A
// fixed-size problem (ProblemOf<5, 2>) runs the solver compiled for those sizes (altro_solver.hpp),
// a dynamic one the solver compiled once in the library.
template <int Nx, int Nu>
AltroResult solve(const ProblemOf<Nx, Nu>& problem, const Eigen::VectorXd& x0,
                  const std::vector<Eigen::VectorXd>& initial_controls,
                  const AltroSettings& settings = {});

}  // namespace diffpills::trajopt

#include "diffpills/trajopt/altro_solver.hpp"  // the template's definition
