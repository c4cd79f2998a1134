#include "ipopt_run.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <string>

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

std::string ipopt_status_text(int status) {
  const auto with_code = [status](const char* what) {
    return std::string(what) + " (" + std::to_string(status) + ")";
  };
  switch (status) {
    case Ipopt::Solve_Succeeded:
      return "solved";
    case Ipopt::Solved_To_Acceptable_Level:
      return with_code("acceptable point");
    case Ipopt::Infeasible_Problem_Detected:
      return with_code("locally infeasible");
    case Ipopt::Maximum_Iterations_Exceeded:
      return with_code("iteration limit");
    case Ipopt::Maximum_CpuTime_Exceeded:
      return with_code("time limit");
    default:
      return with_code("stopped");
  }
}

IpoptRun solve_timed(const Ipopt::SmartPtr<Ipopt::TNLP>& nlp, const IpoptRun& result,
                     IpoptHessian hessian, double max_cpu_seconds) {
  // Ipopt refuses a limit <= 0 with a message on its own output and keeps its default, which
  // would run without the limit asked for.
  if (!(max_cpu_seconds > 0.0)) {
    throw std::invalid_argument("max_cpu_seconds: must be positive, got " +
                                std::to_string(max_cpu_seconds));
  }
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetStringValue("hessian_approximation", to_string(hessian));
  app->Options()->SetNumericValue("tol", 1e-8);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-6);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetNumericValue("max_cpu_time", max_cpu_seconds);
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
  run.max_cpu_seconds = max_cpu_seconds;
  run.status = ipopt_status_text(status);
  if (Ipopt::SmartPtr<Ipopt::SolveStatistics> statistics = app->Statistics(); IsValid(statistics)) {
    run.iterations = statistics->IterationCount();
  }
  return run;
}

PointValues evaluate_point(Ipopt::TNLP& nlp, Ipopt::Index n, const Ipopt::Number* z,
                           Ipopt::Index m) {
  PointValues values;
  values.constraints.resize(static_cast<std::size_t>(m));
  nlp.eval_f(n, z, true, values.cost);
  nlp.eval_g(n, z, false, m, values.constraints.data());
  return values;
}

}  // namespace diffpills::examples
