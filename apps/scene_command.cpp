#include "scene_command.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <new>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "json_io.hpp"
#include "json_line.hpp"

namespace diffpills::app {
namespace {

using json = nlohmann::json;

nlohmann::ordered_json answer(const Scene& scene, double default_margin, const json& query) {
  if (!query.is_object()) {
    throw std::invalid_argument("query: must be a JSON object with a field \"poses\"");
  }
  for (const auto& item : query.items()) {
    if (item.key() != "poses" && item.key() != "margin") {
      throw std::invalid_argument(item.key() + ": unknown field");
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
    if (index < 0) {
      throw std::invalid_argument("poses." + item.key() + ": no body is named '" + item.key() +
                                  "'");
    }
    poses[static_cast<std::size_t>(index)] = parse_pose(item.value(), "poses." + item.key());
    posed[static_cast<std::size_t>(index)] = true;
  }
  for (int i = 0; i < scene.size(); ++i) {
    if (!posed[static_cast<std::size_t>(i)]) {
      throw std::invalid_argument("poses: body '" + scene.body(i).name() + "' has no pose");
    }
  }
  nlohmann::ordered_json contacts = nlohmann::ordered_json::array();
  for (const Contact& contact : scene.contacts(poses, margin)) {
    contacts.push_back(to_json(contact, scene));
  }
  return {{"contacts", std::move(contacts)}};
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
  json value;
  try {
    value = parse_json_line(text);
  } catch (const std::bad_alloc&) {
    throw std::invalid_argument("not enough memory to parse the scene file");
  } catch (const std::invalid_argument& error) {
    // The line parser names the whole text "query"; here it is the file.
    const std::string message = error.what();
    throw std::invalid_argument(message.rfind("query: ", 0) == 0 ? message.substr(7) : message);
  }
  return parse_scene(value);
}

// A margin argument: a finite number of magnitude at most 1e100, the whole argument.
bool parse_margin(const std::string& text, double& margin) {
  if (text.empty()) return false;
  char* end = nullptr;
  margin = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(margin) &&
         std::abs(margin) <= kMaxMagnitude;
}

}  // namespace

std::string answer_scene_line(const Scene& scene, double default_margin, const std::string& line,
                              bool& ok) {
  return answer_line(
      line, [&](const json& query) { return answer(scene, default_margin, query); }, ok);
}

int run_scene_command(const std::vector<std::string>& arguments, std::istream& in,
                      std::ostream& out, std::ostream& diagnostics) {
  std::string path;
  double margin = 0.0;
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--margin") {
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
    diagnostics << "diffpills scene: " << path << ": " << error.what() << "\n";
    return kMisuse;
  }
  return run_lines(in, out, diagnostics,
                   [&](const json& query) { return answer(scene, margin, query); });
}

}  // namespace diffpills::app
