#include "diffpills/trajopt/altro.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace diffpills::trajopt {

void require_size(const Eigen::VectorXd& v, Eigen::Index size, const char* name) {
  if (v.size() != size) {
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) +
                                " entries, got " + std::to_string(v.size()));
  }
}

namespace detail {

void check_settings(const AltroSettings& settings) {
  const auto require = [](bool holds, const char* name, const char* rule) {
    if (!holds) {
      throw std::invalid_argument(std::string("trajopt: AltroSettings::") + name + " must be " +
                                  rule);
    }
  };
  const auto positive = [&](double value, const char* name) {
    require(std::isfinite(value) && value > 0.0, name, "finite and positive");
  };
  const auto growth = [&](double value, const char* name) {
    require(std::isfinite(value) && value >= 1.0, name, "finite and at least 1");
  };
  const auto tolerance = [&](double value, const char* name) {
    require(value >= 0.0, name, "zero or more (not NaN)");
  };
  positive(settings.penalty_initial, "penalty_initial");
  growth(settings.penalty_scaling, "penalty_scaling");
  positive(settings.penalty_max, "penalty_max");
  positive(settings.regularization_initial, "regularization_initial");
  positive(settings.regularization_min, "regularization_min");
  positive(settings.regularization_max, "regularization_max");
  growth(settings.regularization_growth, "regularization_growth");
  tolerance(settings.constraint_tolerance, "constraint_tolerance");
  tolerance(settings.cost_tolerance, "cost_tolerance");
  tolerance(settings.gradient_tolerance, "gradient_tolerance");
  tolerance(settings.polish_tolerance, "polish_tolerance");
  require(
      settings.line_search_lower >= 0.0 && settings.line_search_lower <= settings.line_search_upper,
      "line_search_lower", "in [0, line_search_upper]");
}

}  // namespace detail

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
