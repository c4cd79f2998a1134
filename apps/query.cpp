#include "query.hpp"

#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "json_io.hpp"
#include "json_line.hpp"

namespace diffpills::app {
namespace {

using json = nlohmann::json;

const std::string kQueryLine = "a JSON object with fields \"a\" and \"b\"";

// An optional true/false field, false when absent.
bool flag(const json& query, const char* key) {
  if (!query.contains(key)) return false;
  if (!query[key].is_boolean())
    throw std::invalid_argument(std::string(key) + ": must be true or false");
  return query[key].get<bool>();
}

nlohmann::ordered_json answer_valid_query(const json& query) {
  if (!query.is_object()) {
    throw std::invalid_argument("query: must be " + kQueryLine);
  }
  static const std::set<std::string> allowed = {
      "a", "b", "hessian", "jacobian", "method", "shape_gradient", "signed_distance"};
  for (const auto& item : query.items()) {
    if (allowed.count(item.key()) == 0) {
      throw std::invalid_argument(key_text(item.key()) + ": unknown field");
    }
  }
  for (const char* key : {"a", "b"}) {
    if (!query.contains(key)) throw std::invalid_argument(std::string(key) + ": missing");
  }
  const PosedShape a = parse_posed_shape(query["a"], "a");
  const PosedShape b = parse_posed_shape(query["b"], "b");
  const bool jacobian = flag(query, "jacobian");
  const bool signed_distance = flag(query, "signed_distance");
  const bool shape_gradient = flag(query, "shape_gradient");
  const bool hessian = flag(query, "hessian");
  ProximityOptions options;
  if (query.contains("method")) {
    const json& method = query["method"];
    if (method == "default") {
      options.method = Method::kDefault;
    } else if (method == "interior_point") {
      options.method = Method::kInteriorPoint;
    } else {
      throw std::invalid_argument("method: must be \"default\" or \"interior_point\"");
    }
  }
  // Released, not destroyed, if building it throws (json_line.hpp's release).
  Released<nlohmann::ordered_json> answer(
      jacobian ? to_json(proximity_jacobian(a.shape, a.pose, b.shape, b.pose, options))
               : to_json(proximity(a.shape, a.pose, b.shape, b.pose, options)));
  nlohmann::ordered_json& out = answer.value;
  if (hessian) {
    out["hessian"] =
        matrix_rows(proximity_with_hessian(a.shape, a.pose, b.shape, b.pose, options).hessian);
  }
  if (shape_gradient) {
    out["shape_gradient"] =
        to_json(proximity_shape_gradient(a.shape, a.pose, b.shape, b.pose, options).shape_gradient);
  }
  if (signed_distance) {  // (one method: "method" chooses the proximity's solver)
    out["signed_distance"] =
        jacobian ? to_json(signed_distance_jacobian(a.shape, a.pose, b.shape, b.pose))
                 : to_json(diffpills::signed_distance(a.shape, a.pose, b.shape, b.pose));
    if (hessian) {
      out["signed_distance"]["hessian"] =
          matrix_rows(signed_distance_hessian(a.shape, a.pose, b.shape, b.pose).hessian);
    }
    if (shape_gradient) {
      out["signed_distance"]["shape_gradient"] =
          to_json(signed_distance_shape_gradient(a.shape, a.pose, b.shape, b.pose).shape_gradient);
    }
  }
  return std::move(out);
}

// A query line's answer. The interior-point method's failures (SolverError: its iteration cap, or
// a point outside a spike sharper than its tolerance) are answered as errors of the field that
// chose it.
nlohmann::ordered_json answer(const json& query) {
  try {
    return answer_valid_query(query);
  } catch (const SolverError& failure) {
    std::string reason = failure.what();
    const std::string prefix = "diffpills: ";
    if (reason.compare(0, prefix.size(), prefix) == 0) reason.erase(0, prefix.size());
    throw std::runtime_error("method: \"interior_point\" failed: " + reason);
  }
}

}  // namespace

std::string answer_query_line(const std::string& line, bool& ok) {
  return answer_line(line, kQueryLine, answer, ok);
}

int run_query(std::istream& in, std::ostream& out, std::ostream& diagnostics) {
  return run_lines(in, out, diagnostics, kQueryLine, answer);
}

}  // namespace diffpills::app
