#include "solver_runs.hpp"

#include <chrono>
#include <cmath>

#include "demo_json.hpp"

namespace diffpills::examples {

AltroRun fastest_altro(int runs, const std::function<trajopt::AltroResult()>& solve) {
  AltroRun fastest;
  fastest.solve_ms = INFINITY;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    trajopt::AltroResult result = solve();
    const std::chrono::duration<double, std::milli> elapsed =
        std::chrono::steady_clock::now() - start;
    if (elapsed.count() < fastest.solve_ms) fastest = {std::move(result), elapsed.count()};
  }
  return fastest;
}

IpoptRuns fastest_ipopt(int runs, const std::function<IpoptRun(IpoptHessian)>& solve) {
  // A solved run ranks before one that did not solve, then the faster: a run stopped by the CPU
  // limit can end sooner on the wall clock than one of the same solver that solved.
  const auto better = [](const IpoptRun& a, const IpoptRun& b) {
    return a.solved != b.solved ? a.solved : a.solve_ms < b.solve_ms;
  };
  IpoptRuns fastest;
  for (const IpoptHessian hessian : {IpoptHessian::kLimitedMemory, IpoptHessian::kExact}) {
    IpoptRun& best = hessian == IpoptHessian::kExact ? fastest.exact : fastest.limited_memory;
    for (int run = 0; run < runs; ++run) {
      IpoptRun next = solve(hessian);
      if (run == 0 || better(next, best)) best = std::move(next);
    }
  }
  return fastest;
}

const IpoptRun* IpoptRuns::faster_solved() const {
  const IpoptRun* faster = nullptr;
  for (const IpoptRun* run : {&limited_memory, &exact}) {
    if (run->solved && (faster == nullptr || run->solve_ms < faster->solve_ms)) faster = run;
  }
  return faster;
}

bool same_minimum(double cost, double altro_cost) {
  return std::abs(cost - altro_cost) <= 0.01 * std::abs(altro_cost);
}

void add_ipopt_comparison(nlohmann::ordered_json& out, const std::optional<IpoptRuns>& ipopt,
                          const trajopt::AltroResult& altro, double altro_ms, int runs) {
  if (!ipopt) return;
  out["ipopt"] = ipopt_summary(ipopt->limited_memory);
  out["ipopt_exact"] = ipopt_summary(ipopt->exact);
  const IpoptRun* faster = ipopt->faster_solved();
  if (faster == nullptr) {
    out["altro_speedup"] = nullptr;
    return;
  }
  out["altro_speedup"] = {{"over", to_string(faster->hessian)},
                          {"ratio", faster->solve_ms / altro_ms},
                          {"runs", runs},
                          {"same_minimum", same_minimum(faster->cost, altro.cost)}};
}

}  // namespace diffpills::examples
