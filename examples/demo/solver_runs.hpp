// How the demo times its solvers, every one of a problem the same way: the fastest of the same
// number of runs (no solver gets more tries than another; with several, no time is a cold-cache
// outlier), ALTRO timed around trajopt::solve, Ipopt around its solve alone (timed_solve.hpp);
// Ipopt with both of its Hessians (limited-memory and exact), and ALTRO's speed-up over the
// faster of the two that solved.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>

#include "diffpills/trajopt/altro.hpp"
#include "ipopt/ipopt_run.hpp"

namespace diffpills::examples {

// What `diffpills_demo` runs: `repetitions` of each solver per problem (car-bus and quadrotor;
// the arm's runs take seconds to minutes for Ipopt, so it runs each solver once), and Ipopt on
// the quadrotor and the arm too unless `quick` (the tests' setting: one run each, Ipopt on the
// car-bus only).
//
// Every Ipopt run stops after ipopt_cpu_seconds of CPU time (Ipopt counts user time only; the
// command line's --ipopt-cpu-seconds). The car-bus runs take milliseconds; from the same guess as
// ALTRO, Ipopt's path on the quadrotor and the arm turns on the last bits of the
// arithmetic: a relative change of 1e-14 in the quadrotor's guess takes it anywhere from a point of
// cost 6 in 400 iterations to its 3,000-iteration limit (27 s), and the arm's exact-Hessian run has
// taken from 390 iterations (66 s) to the limit (~15 minutes) (BENCHMARKS.md, 2026-11-28). The
// limit keeps `make demo` to minutes whichever path this build's rounding takes.
struct DemoSettings {
  int repetitions = 3;
  bool quick = false;
  double ipopt_cpu_seconds = kComparisonCpuSeconds;
  int runs(bool slow) const { return quick || slow ? 1 : repetitions; }
};

struct AltroRun {
  trajopt::AltroResult result;
  double solve_ms = 0.0;
};
AltroRun fastest_altro(int runs, const std::function<trajopt::AltroResult()>& solve);

struct IpoptRuns {
  IpoptRun limited_memory, exact;
  // The faster of the runs that solved, or nullptr if neither did.
  const IpoptRun* faster_solved() const;
};
// solve(hessian) runs Ipopt once with that Hessian; each Hessian's fastest solved run of `runs`,
// or its fastest run if none solved.
IpoptRuns fastest_ipopt(int runs, const std::function<IpoptRun(IpoptHessian)>& solve);

// Whether two solvers' costs are one local minimum's (within 1%): a speed-up between different
// minima compares different answers.
bool same_minimum(double cost, double altro_cost);

// The "ipopt" (limited-memory) and "ipopt_exact" blocks (demo_json.hpp's ipopt_summary), and
// "altro_speedup": {"over": the faster solved Ipopt's Hessian, "ratio": its solve_ms over ALTRO's,
// "runs": runs per solver, "same_minimum": same_minimum of the two costs}, null if neither Ipopt
// run solved; nothing without Ipopt runs.
void add_ipopt_comparison(nlohmann::ordered_json& out, const std::optional<IpoptRuns>& ipopt,
                          const trajopt::AltroResult& altro, double altro_ms, int runs);

}  // namespace diffpills::examples
