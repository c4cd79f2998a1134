// JSON pieces the demo's problem files share.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "diffpills/trajopt/altro.hpp"
#include "ipopt/ipopt_run.hpp"

namespace diffpills::examples {

// Writes text to path, or throws std::runtime_error naming the path (a folder that cannot be
// written, a full disk): a demo that wrote nothing must not say where its files are.
void write_file(const std::filesystem::path& path, const std::string& text);

// A vector as a JSON list of numbers.
nlohmann::ordered_json json_list(const Eigen::VectorXd& v);

// The "solver" block: name, status, iterations, outer and polish iterations, max_violation, cost
// and solve_ms.
nlohmann::ordered_json altro_summary(const trajopt::AltroResult& result, double solve_ms);

// An Ipopt block: hessian ("limited-memory" or "exact"), status, iterations, max_violation, cost
// (both null when Ipopt handed back no point: IpoptRun::has_point), solve_ms and max_cpu_seconds
// (the run's CPU limit).
nlohmann::ordered_json ipopt_summary(const IpoptRun& run);

}  // namespace diffpills::examples
