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

// Ipopt's own limit on a run's CPU seconds (its option max_cpu_time) when none is asked for.
inline constexpr double kNoIpoptTimeLimit = 1e6;
// The limit on each Ipopt run of the demo and of the benchmarks (solver_runs.hpp's DemoSettings
// says why there is one).
inline constexpr double kComparisonCpuSeconds = 120.0;

// What an Ipopt return status means, as the runs report it: "solved" for Solve_Succeeded, else
// what stopped the run and Ipopt's code: "acceptable point (1)" (Solved_To_Acceptable_Level: the
// tolerances were not reached, looser ones were for 15 iterations), "locally infeasible (2)",
// "iteration limit (-1)", "time limit (-4)", "stopped (N)" for the rest (IpReturnCodes_inc.h).
std::string ipopt_status_text(int status);

struct IpoptRun {
  IpoptHessian hessian = IpoptHessian::kLimitedMemory;
  bool solved = false;
  std::string status;  // ipopt_status_text
  int iterations = 0;
  double cost = 0.0;
  double max_violation = 0.0;  // the largest dynamics defect or constraint violation
  double solve_ms = 0.0;
  double max_cpu_seconds = kNoIpoptTimeLimit;  // the run's CPU limit (Ipopt's max_cpu_time)
  std::vector<Eigen::VectorXd> states, controls;
  // Whether Ipopt handed back its last point (its finalize_solution, which it skips for errors
  // before it starts, such as an option out of range): the cost, max_violation, states and
  // controls are that point's, evaluated from it.
  bool has_point() const { return !states.empty(); }
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
