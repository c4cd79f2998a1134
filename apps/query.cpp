#include "query.hpp"

#include <istream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>

#include "json_io.hpp"

namespace diffpills::app {
namespace {

using json = nlohmann::ordered_json;

json answer(const json& query) {
  if (!query.is_object()) {
    throw std::invalid_argument("query: must be a JSON object with fields \"a\" and \"b\"");
  }
  static const std::set<std::string> allowed = {"a", "b", "jacobian", "method"};
  for (const auto& item : query.items()) {
    if (allowed.count(item.key()) == 0) {
      throw std::invalid_argument(item.key() + ": unknown field");
    }
  }
  for (const char* key : {"a", "b"}) {
    if (!query.contains(key)) throw std::invalid_argument(std::string(key) + ": missing");
  }
  const PosedShape a = parse_posed_shape(query["a"], "a");
  const PosedShape b = parse_posed_shape(query["b"], "b");
  bool jacobian = false;
  if (query.contains("jacobian")) {
    if (!query["jacobian"].is_boolean())
      throw std::invalid_argument("jacobian: must be true or false");
    jacobian = query["jacobian"].get<bool>();
  }
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
  if (jacobian) {
    return to_json(proximity_jacobian(a.shape, a.pose, b.shape, b.pose, options));
  }
  return to_json(proximity(a.shape, a.pose, b.shape, b.pose, options));
}

}  // namespace

std::string answer_query_line(const std::string& line, bool& ok) {
  ok = false;
  json query;
  try {
    query = json::parse(line);
  } catch (const json::exception& error) {
    // Syntax errors, and numbers JSON allows but a double cannot hold (1e999). NaN and Infinity
    // are not JSON at all, so a non-finite value can only arrive as one of these.
    return json{{"error", std::string("malformed JSON (numbers must be finite; NaN and Infinity "
                                      "are not JSON): ") +
                              error.what()}}
        .dump();
  }
  try {
    json result = answer(query);
    ok = true;
    return result.dump();
  } catch (const std::exception& error) {
    return json{{"error", error.what()}}.dump();
  }
}

int run_query(std::istream& in, std::ostream& out) {
  int status = 0;
  std::string line;
  while (std::getline(in, line)) {
    bool ok = false;
    out << answer_query_line(line, ok) << '\n' << std::flush;
    if (!ok) status = 1;
  }
  return status;
}

}  // namespace diffpills::app
