#include "diffpills/trajopt/altro.hpp"

#include <stdexcept>
#include <string>

namespace diffpills::trajopt {

void require_size(const Eigen::VectorXd& v, Eigen::Index size, const char* name) {
  if (v.size() != size) {
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) +
                                " entries, got " + std::to_string(v.size()));
  }
}

const char* to_string(AltroStatus status) {
  switch (status) {
    case AltroStatus::kSolved:
      return "solved";
    case AltroStatus::kMaxIterations:
      return "max_iterations";
    case AltroStatus::kRegularizationFailure:
      return "regularization_failure";
    case AltroStatus::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

// The run-time-sized solver, compiled once here for every dynamic Problem.
template class detail::AltroSolver<Eigen::Dynamic, Eigen::Dynamic>;

}  // namespace diffpills::trajopt
