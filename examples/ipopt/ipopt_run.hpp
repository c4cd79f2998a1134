// What the Ipopt cross-checks share (problem_nlp.hpp for any trajopt::Problem, car_bus_ipopt.hpp):
// the result of a run and the starting states; the solve itself is timed_solve.hpp.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "diffpills/trajopt/dynamic_problem.hpp"
#include "diffpills/trajopt/problem.hpp"

namespace diffpills::examples {

// How Ipopt gets the Hessian of the Lagrangian: its limited-memory quasi-Newton approximation
// (L-BFGS, from first derivatives alone), or exact, from the problem's second derivatives
// (problem.hpp's dynamics_hessian and constraint_hessian and the costs' exact Hessians).
enum class IpoptHessian { kLimitedMemory, kExact };
const char* to_string(IpoptHessian hessian);  // "limited-memory", "exact"

struct IpoptRun {
  IpoptHessian hessian = IpoptHessian::kLimitedMemory;
  bool solved = false;
  std::string status;
  int iterations = 0;
  double cost = 0.0;
  double max_violation = 0.0;  // the largest dynamics defect or constraint violation
  double solve_ms = 0.0;
  std::vector<Eigen::VectorXd> states, controls;
};

// x0 and the states the controls lead to through the problem's dynamics: Ipopt starts from this
// rollout, as ALTRO does.
std::vector<Eigen::VectorXd> rollout(const trajopt::Problem& problem, const Eigen::VectorXd& x0,
                                     const std::vector<Eigen::VectorXd>& controls);
template <int Nx, int Nu>
std::vector<Eigen::VectorXd> rollout(const trajopt::ProblemOf<Nx, Nu>& problem,
                                     const Eigen::VectorXd& x0,
                                     const std::vector<Eigen::VectorXd>& controls) {
  return rollout(trajopt::DynamicProblem<Nx, Nu>(problem), x0, controls);
}

}  // namespace diffpills::examples
