// The arm-and-shelf problem in `make demo` (issue 11): solve it with ALTRO from the retreating
// guess (the joint-space straight line collides), cross-check with Ipopt from the same guess, then
// write arm_shelf.csv, .json and .svg.
#pragma once

#include <filesystem>
#include <optional>

#include "arm_shelf/arm_shelf.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "solver_runs.hpp"

namespace diffpills::examples {

struct ArmShelfRun {
  trajopt::AltroResult result;
  double solve_ms = 0.0;
  double min_distance = 0.0;       // smallest signed distance over the checked pairs and knots
  double path_min_distance = 0.0;  // the same between knots too, 20 samples per step
  double straight_line_min_distance = 0.0;  // over the straight line's knots
  int runs = 1;                             // per solver
  std::optional<IpoptRuns> ipopt;           // the same problem from the same guess (not when quick)
};

// ALTRO and Ipopt (both Hessians) from the retreating guess, each solved settings.runs(true)
// times (once: Ipopt's runs take seconds to minutes) and its fastest run kept.
ArmShelfRun solve_arm_shelf(const ArmShelfProblem& problem, const DemoSettings& settings);

// A header line "t,q1,q2,q3,q4,q5,q6,q7", then one row per knot.
void write_arm_shelf_csv(const ArmShelfProblem& problem, const ArmShelfRun& run,
                         const std::filesystem::path& path);
// The keys issue 11 lists (dh, flange_d, joint_limits, links, excluded_link_pairs, shelf, start,
// goal, status, iterations, ms, min_distance) and more: knots, dt, clearance, velocity_limits,
// cost, max_violation, path_min_distance, straight_line_min_distance, the solver and Ipopt
// blocks.
void write_arm_shelf_json(const ArmShelfProblem& problem, const ArmShelfRun& run,
                          const std::filesystem::path& path);
// Views from behind the robot (along +x) and from its right (along +y) of the shelf and of the arm
// at five knots, with the flange's path.
void write_arm_shelf_svg(const ArmShelfProblem& problem, const ArmShelfRun& run,
                         const std::filesystem::path& path);

}  // namespace diffpills::examples
