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
  IpoptRuns fastest;
  for (const IpoptHessian hessian : {IpoptHessian::kLimitedMemory, IpoptHessian::kExact}) {
    IpoptRun& best = hessian == IpoptHessian::kExact ? fastest.exact : fastest.limited_memory;
    for (int run = 0; run < runs; ++run) {
      IpoptRun next = solve(hessian);
      if (run == 0 || next.solve_ms < best.solve_ms) best = std::move(next);
    }
  }
  return fastest;
}

void add_ipopt_comparison(nlohmann::ordered_json& out, const std::optional<IpoptRuns>& ipopt,
                          double altro_ms, int runs) {
  if (!ipopt) return;
  out["ipopt"] = ipopt_summary(ipopt->limited_memory);
  out["ipopt_exact"] = ipopt_summary(ipopt->exact);
  out["altro_speedup"] = {{"over", to_string(ipopt->faster().hessian)},
                          {"ratio", ipopt->faster().solve_ms / altro_ms},
                          {"runs", runs}};
}

}  // namespace diffpills::examples
