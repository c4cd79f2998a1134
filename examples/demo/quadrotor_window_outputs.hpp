// The quadrotor-window problem in `make demo`: solve it, then write quadrotor_window.csv, .json and
// .svg (top, side and front views).
#pragma once

#include <filesystem>
#include <optional>

#include "diffpills/trajopt/altro.hpp"
#include "quadrotor_window/quadrotor_window.hpp"
#include "solver_runs.hpp"

namespace diffpills::examples {

struct QuadrotorWindowRun {
  trajopt::AltroResult result;
  double solve_ms = 0.0;
  // The level body slid along the straight line from start to goal (no dynamics): it cannot pass
  // the window, which this negative number shows.
  double level_straight_line_min_phi = 0.0;
  double min_phi = 0.0;            // over the solution's knots and obstacles
  double largest_tilt_deg = 0.0;   // angle between body z and world z, over the knots
  int runs = 1;                    // per solver
  std::optional<IpoptRuns> ipopt;  // the same problem from the same guess (not when quick)
};

// ALTRO and Ipopt (both Hessians) from hover, each the fastest of settings.runs(false) solves.
QuadrotorWindowRun solve_quadrotor_window(const QuadrotorWindowProblem& problem,
                                          const DemoSettings& settings);

// CSV header: k,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,u1,u2,u3,u4 (the last row's controls
// empty).
void write_quadrotor_window_csv(const QuadrotorWindowProblem& problem,
                                const QuadrotorWindowRun& run, const std::filesystem::path& path);
void write_quadrotor_window_json(const QuadrotorWindowProblem& problem,
                                 const QuadrotorWindowRun& run, const std::filesystem::path& path);
void write_quadrotor_window_svg(const QuadrotorWindowProblem& problem,
                                const QuadrotorWindowRun& run, const std::filesystem::path& path);

}  // namespace diffpills::examples
