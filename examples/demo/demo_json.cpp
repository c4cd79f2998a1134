#include "demo_json.hpp"

#include <fstream>
#include <stdexcept>
#include <vector>

namespace diffpills::examples {

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

nlohmann::ordered_json json_list(const Eigen::VectorXd& v) {
  return nlohmann::ordered_json(std::vector<double>(v.data(), v.data() + v.size()));
}

nlohmann::ordered_json altro_summary(const trajopt::AltroResult& result, double solve_ms) {
  return {{"name", "altro"},
          {"status", trajopt::to_string(result.status)},
          {"iterations", result.iterations},
          {"outer_iterations", result.outer_iterations},
          {"polish_iterations", result.polish_iterations},
          {"max_violation", result.max_violation},
          {"cost", result.cost},
          {"solve_ms", solve_ms}};
}

nlohmann::ordered_json ipopt_summary(const IpoptRun& run) {
  const auto of_point = [&run](double value) {
    return run.has_point() ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
  };
  return {{"hessian", to_string(run.hessian)},
          {"status", run.status},
          {"iterations", run.iterations},
          {"max_violation", of_point(run.max_violation)},
          {"cost", of_point(run.cost)},
          {"solve_ms", run.solve_ms},
          {"max_cpu_seconds", run.max_cpu_seconds}};
}

}  // namespace diffpills::examples
