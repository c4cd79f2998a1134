// Any trajopt::Problem as a nonlinear program for Ipopt, to cross-check the ALTRO solver on the
// same discretization, costs and constraints:
//   variables   z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}]
//   minimize    sum_k l_k(x_k, u_k) + l_N(x_{N-1})
//   subject to  x_{k+1} - f(x_k, u_k) = 0,  e_k(x_k, u_k) = 0,  c_k(x_k, u_k) <= 0,
//               x_0 = the given initial state (variable bounds)
// with the problem's exact first derivatives (dense per knot) and either Ipopt's limited-memory
// Hessian approximation or the exact Hessian of the Lagrangian from the problem's second
// derivatives (block diagonal by knot: knot_hessian.hpp), started from the rollout of the initial
// controls, as ALTRO is. kExact needs problem.has_second_derivatives() (else
// std::invalid_argument). A run stops after max_cpu_seconds of CPU time (status "time limit (-4)").
// A fixed-size problem is seen through trajopt::DynamicProblem.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "diffpills/trajopt/dynamic_problem.hpp"
#include "diffpills/trajopt/problem.hpp"
#include "ipopt_run.hpp"

namespace diffpills::examples {

IpoptRun solve_problem_with_ipopt(const trajopt::Problem& problem, const Eigen::VectorXd& x0,
                                  const std::vector<Eigen::VectorXd>& initial_controls,
                                  IpoptHessian hessian = IpoptHessian::kLimitedMemory,
                                  double max_cpu_seconds = kNoIpoptTimeLimit);

template <int Nx, int Nu>
IpoptRun solve_problem_with_ipopt(const trajopt::ProblemOf<Nx, Nu>& problem,
                                  const Eigen::VectorXd& x0,
                                  const std::vector<Eigen::VectorXd>& initial_controls,
                                  IpoptHessian hessian = IpoptHessian::kLimitedMemory,
                                  double max_cpu_seconds = kNoIpoptTimeLimit) {
  return solve_problem_with_ipopt(trajopt::DynamicProblem<Nx, Nu>(problem), x0, initial_controls,
                                  hessian, max_cpu_seconds);
}

}  // namespace diffpills::examples
