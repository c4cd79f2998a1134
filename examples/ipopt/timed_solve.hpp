// The solve of the Ipopt cross-checks, with one set of options (used by problem_nlp.cpp and
// car_bus_ipopt.cpp only: it needs Ipopt's headers, which the examples' users do not).
#pragma once

#include <IpTNLP.hpp>
#include <vector>

#include "ipopt_run.hpp"

namespace diffpills::examples {

// Solves nlp with the given Hessian (the NLP's eval_h for kExact), tol 1e-8, constr_viol_tol 1e-6,
// at most 3,000 iterations and max_cpu_seconds of CPU time (no options file), timing the solve
// alone (not option parsing); std::invalid_argument unless max_cpu_seconds > 0. `result` is where
// the NLP's finalize_solution writes, read after the solve; the run returned is it with the Hessian
// used, the status, the iteration count and the time.
IpoptRun solve_timed(const Ipopt::SmartPtr<Ipopt::TNLP>& nlp, const IpoptRun& result,
                     IpoptHessian hessian, double max_cpu_seconds = kNoIpoptTimeLimit);

// The objective and the m constraint values of nlp at the point z (n variables) that Ipopt hands to
// its finalize_solution, evaluated by nlp's own eval_f and eval_g: Ipopt 3.11 hands back zeros for
// both when it stops at the time limit, so the runs never read its values.
struct PointValues {
  double cost = 0.0;
  std::vector<Ipopt::Number> constraints;
};
PointValues evaluate_point(Ipopt::TNLP& nlp, Ipopt::Index n, const Ipopt::Number* z,
                           Ipopt::Index m);

}  // namespace diffpills::examples
