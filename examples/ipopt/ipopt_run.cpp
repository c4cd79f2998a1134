#include "ipopt_run.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <chrono>

#include "timed_solve.hpp"

namespace diffpills::examples {

std::vector<Eigen::VectorXd> rollout(const trajopt::Problem& problem, const Eigen::VectorXd& x0,
                                     const std::vector<Eigen::VectorXd>& controls) {
  std::vector<Eigen::VectorXd> states{x0};
  for (const Eigen::VectorXd& u : controls) {
    Eigen::VectorXd next;
    Eigen::MatrixXd A, B;
    problem.dynamics(states.back(), u, next, A, B);
    states.push_back(next);
  }
  return states;
}

const char* to_string(IpoptHessian hessian) {
  return hessian == IpoptHessian::kExact ? "exact" : "limited-memory";
}

IpoptRun solve_timed(const Ipopt::SmartPtr<Ipopt::TNLP>& nlp, const IpoptRun& result,
                     IpoptHessian hessian) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetStringValue("hessian_approximation", to_string(hessian));
  app->Options()->SetNumericValue("tol", 1e-8);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-6);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");  // no banner
  // "": no options file. Ipopt otherwise reads ./ipopt.opt, and the runs would depend on the
  // folder they are started from.
  Ipopt::ApplicationReturnStatus status = app->Initialize("");
  double solve_ms = 0.0;
  if (status == Ipopt::Solve_Succeeded) {
    const auto start = std::chrono::steady_clock::now();
    status = app->OptimizeTNLP(nlp);
    const std::chrono::duration<double, std::milli> elapsed =
        std::chrono::steady_clock::now() - start;
    solve_ms = elapsed.count();
  }
  IpoptRun run = result;
  run.hessian = hessian;
  run.solve_ms = solve_ms;
  run.status =
      status == Ipopt::Solve_Succeeded ? "solved" : "failed (" + std::to_string(status) + ")";
  if (Ipopt::SmartPtr<Ipopt::SolveStatistics> statistics = app->Statistics(); IsValid(statistics)) {
    run.iterations = statistics->IterationCount();
  }
  return run;
}

}  // namespace diffpills::examples
