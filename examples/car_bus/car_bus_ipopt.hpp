// The car-bus problem as a nonlinear program for Ipopt, to cross-check the ALTRO solver: the same
// discretization, costs and constraints (CarBusProblem), written as
//   variables   z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}]
//   minimize    the same costs
//   subject to  x_{k+1} - f(x_k, u_k) = 0,  phi(x_k) >= 0,
//               x_0 = x0 and the final position and heading = goal (variable bounds),
//               |u| <= control_limit (variable bounds)
// with exact first derivatives and either Ipopt's limited-memory Hessian approximation or the
// exact Hessian of the Lagrangian (the costs', the car's RK4 step's and phi's through the pose).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "car_bus.hpp"
#include "ipopt/ipopt_run.hpp"

namespace diffpills::examples {

// Starts from the rollout of initial_controls, as ALTRO does; stops after max_cpu_seconds of CPU
// time (std::invalid_argument unless it is > 0; timed_solve.hpp).
IpoptRun solve_with_ipopt(const CarBusProblem& problem,
                          const std::vector<Eigen::VectorXd>& initial_controls,
                          IpoptHessian hessian = IpoptHessian::kLimitedMemory,
                          double max_cpu_seconds = kNoIpoptTimeLimit);

}  // namespace diffpills::examples
