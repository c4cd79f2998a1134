#include "scene_command.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <new>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "json_io.hpp"
#include "json_line.hpp"
#include "json_lines.hpp"

namespace diffpills::app {
namespace {

using json = nlohmann::json;

const std::string kSceneLine = "a JSON object with a field \"poses\"";
const std::string kSceneFile = "a JSON object with a field \"bodies\"";

nlohmann::ordered_json answer(const Scene& scene, double default_margin, const json& query) {
  if (!query.is_object()) {
    throw std::invalid_argument("query: must be " + kSceneLine);
  }
  for (const auto& item : query.items()) {
    if (item.key() != "poses" && item.key() != "margin") {
      throw std::invalid_argument(key_text(item.key()) + ": unknown field");
    }
  }
  double margin = default_margin;
  if (query.contains("margin")) {
    if (!query["margin"].is_number()) throw std::invalid_argument("margin: must be a number");
    margin = query["margin"].get<double>();
  }
  if (!query.contains("poses")) throw std::invalid_argument("poses: missing");
  const json& given = query["poses"];
  if (!given.is_object()) {
    throw std::invalid_argument(
        "poses: must be an object of {\"r\": [3], \"q\": [4]} by body name");
  }
  std::vector<Pose> poses(static_cast<std::size_t>(scene.size()));
  std::vector<bool> posed(static_cast<std::size_t>(scene.size()), false);
  for (const auto& item : given.items()) {
    const int index = scene.index_of(item.key());
    const std::string name = key_text(item.key());
    const std::string field = "poses." + name;
    if (index < 0) {
      std::string message = field;
      message.append(": no body is named '").append(name).append("'");
      throw std::invalid_argument(message);
    }
    poses[static_cast<std::size_t>(index)] = parse_pose(item.value(), field);
    posed[static_cast<std::size_t>(index)] = true;
  }
  for (int i = 0; i < scene.size(); ++i) {
    if (!posed[static_cast<std::size_t>(i)]) {
      throw std::invalid_argument("poses: body '" + key_text(scene.body(i).name()) +
                                  "' has no pose");
    }
  }
  std::vector<Contact> found;
  try {
    found = scene.contacts(poses, margin);
  } catch (const BodyPoseError& error) {
    // Named as the line names it: the body's pose is poses.<name>.
    throw std::invalid_argument("poses." + key_text(scene.body(error.body()).name()) + ", shape " +
                                std::to_string(error.shape()) + ": " + error.reason());
  }
  // Released, not destroyed, if building it throws (json_line.hpp's release).
  Released<nlohmann::ordered_json> contacts(nlohmann::ordered_json::array());
  for (const Contact& contact : found) {
    contacts.value.push_back(to_json(contact, scene));
  }
  return {{"contacts", std::move(contacts.value)}};
}

// The scene file, parsed as one JSON text (the limits of a query line apply to it).
Scene load_scene(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::invalid_argument("cannot open the scene file");
  std::string text;
  char buffer[1 << 16];
  while (file.read(buffer, sizeof buffer) || file.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(file.gcount()));
    if (text.size() > kMaxLineBytes) {
      throw std::invalid_argument("the scene file is longer than " + std::to_string(kMaxLineBytes) +
                                  " bytes");
    }
  }
  if (file.bad()) throw std::invalid_argument("cannot read the scene file");
  Released<json> value;  // not destroyed with an allocation (json_line.hpp's release)
  try {
    value.value = parse_json_line(text, kSceneFile);
  } catch (const std::bad_alloc&) {
    throw std::invalid_argument("not enough memory to parse the scene file");
  } catch (const std::invalid_argument& error) {
    // The line parser names the whole text "query" and calls it a line; here it is the file.
    std::string message = error.what();
    if (message.rfind("query: ", 0) == 0) message.erase(0, 7);
    if (message.rfind("empty line", 0) == 0) message.replace(0, 10, "empty file");
    throw std::invalid_argument(message);
  }
  return parse_scene(value.value);
}

// A margin argument: the whole argument a number as JSON writes one (the margin of a line is
// one), of magnitude at most 1e100. strtod alone would also take hex, "inf", leading spaces and
// a leading '+'.
bool parse_margin(const std::string& text, double& margin) {
  static const std::regex json_number(R"(-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?)");
  if (!std::regex_match(text, json_number)) return false;
  margin = std::strtod(text.c_str(), nullptr);
  return std::isfinite(margin) && std::abs(margin) <= kMaxMagnitude;
}

}  // namespace

std::string answer_scene_line(const Scene& scene, double default_margin, const std::string& line,
                              bool& ok) {
  return answer_line(
      line, kSceneLine, [&](const json& query) { return answer(scene, default_margin, query); },
      ok);
}

int run_scene_command(const std::vector<std::string>& arguments, std::istream& in,
                      std::ostream& out, std::ostream& diagnostics) {
  std::string path;
  double margin = 0.0;
  bool margin_given = false;
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--margin" && margin_given) {
      diagnostics << "diffpills scene: --margin given twice\n";
      return kMisuse;
    }
    if (arguments[i] == "--margin") {
      margin_given = true;
      if (i + 1 == arguments.size() || !parse_margin(arguments[i + 1], margin)) {
        diagnostics << "diffpills scene: --margin needs a finite number of magnitude at most "
                       "1e100\n";
        return kMisuse;
      }
      ++i;
    } else if (path.empty() && arguments[i].rfind("--", 0) != 0) {
      path = arguments[i];
    } else {
      diagnostics << "diffpills scene: unexpected argument '" << arguments[i]
                  << "' (usage: diffpills scene SCENE.json [--margin M])\n";
      return kMisuse;
    }
  }
  if (path.empty()) {
    diagnostics << "diffpills scene: missing the scene file (usage: diffpills scene SCENE.json "
                   "[--margin M])\n";
    return kMisuse;
  }
  Scene scene;
  try {
    scene = load_scene(path);
  } catch (const std::exception& error) {
    diagnostics << "diffpills scene: " << path << ": " << error_text(error.what()) << "\n";
    return kMisuse;
  }
  return run_lines(in, out, diagnostics, kSceneLine,
                   [&](const json& query) { return answer(scene, margin, query); });
}

}  // namespace diffpills::app
