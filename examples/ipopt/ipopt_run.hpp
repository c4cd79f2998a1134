// What the Ipopt cross-checks share (problem_nlp.hpp for any trajopt::Problem, car_bus_ipopt.hpp):
// the result of a run and the starting states; the solve itself is timed_solve.hpp.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "diffpills/trajopt/problem.hpp"

namespace diffpills::examples {

struct IpoptRun {
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

}  // namespace diffpills::examples
