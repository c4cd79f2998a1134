// libFuzzer target: arbitrary bytes as the standard input of `diffpills query` (issue 9), and as
// the input of `diffpills scene` (issue 11).
//
// Checked: every line is answered by exactly one line, in order; every answer is valid JSON (in
// UTF-8, whatever bytes the query held), an object holding either "error" (a string) or a finite
// "phi"; the exit status says whether any line was an error. A single line is also answered
// directly by answer_query_line, which must agree with the stream's answer and never throw.
// The same lines are answered as scene queries (a scene of three bodies): one line of valid JSON
// each, "error" or "contacts" with finite distances; and the whole input read as a scene file
// either gives a scene or throws std::invalid_argument, and that scene answers a query posing
// every body at the origin.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "json_io.hpp"
#include "json_line.hpp"
#include "query.hpp"
#include "scene_command.hpp"

namespace {

[[noreturn]] void violated(const char* what, const std::string& text) {
  std::fprintf(stderr, "invariant violated: %s\n%.2000s\n", what, text.c_str());
  std::abort();
}

// Returns true for a result, false for an error answer.
bool check_answer(const std::string& answer) {
  if (answer.find('\n') != std::string::npos) violated("an answer is one line", answer);
  const nlohmann::json parsed = nlohmann::json::parse(answer, nullptr, false);
  if (parsed.is_discarded()) violated("an answer is valid JSON", answer);
  if (!parsed.is_object()) violated("an answer is an object", answer);
  if (parsed.contains("error")) {
    if (!parsed["error"].is_string() || parsed.size() != 1) violated("error answer", answer);
    return false;
  }
  if (!parsed.contains("phi") || !parsed["phi"].is_number() ||
      !std::isfinite(parsed["phi"].get<double>())) {
    violated("a result has a finite phi", answer);
  }
  return true;
}

// Returns true for a contacts answer, false for an error answer.
bool check_scene_answer(const std::string& answer) {
  if (answer.find('\n') != std::string::npos) violated("a scene answer is one line", answer);
  const nlohmann::json parsed = nlohmann::json::parse(answer, nullptr, false);
  if (parsed.is_discarded() || !parsed.is_object())
    violated("a scene answer is a JSON object", answer);
  if (parsed.contains("error")) {
    if (!parsed["error"].is_string() || parsed.size() != 1) violated("scene error answer", answer);
    return false;
  }
  if (!parsed.contains("contacts") || !parsed["contacts"].is_array()) {
    violated("a scene result has contacts", answer);
  }
  for (const auto& contact : parsed["contacts"]) {
    if (!contact["distance"].is_number() || !std::isfinite(contact["distance"].get<double>())) {
      violated("a contact has a finite distance", answer);
    }
  }
  return true;
}

const diffpills::Scene& fixed_scene() {
  static const diffpills::Scene scene = [] {
    Eigen::MatrixX2d C(4, 2);
    C << 1, 0, 0, 1, -1, 0, 0, -1;
    const diffpills::Pose lifted(Eigen::Vector3d(0, 0, 0.1), Eigen::Vector4d(1, 0, 0, 0));
    return diffpills::Scene(
        {diffpills::Body("a", {{diffpills::Capsule(1, 0.1), diffpills::Pose()}}),
         diffpills::Body("b", {{diffpills::PaddedPolygon(C, Eigen::Vector4d::Ones(), 0.1), lifted},
                               {diffpills::Capsule(0, 0.2), diffpills::Pose()}}),
         diffpills::Body("c", {})},
        {{"a", "c"}});
  }();
  return scene;
}

void check_scene_file(const std::string& input) {
  diffpills::Scene scene;
  try {
    scene = diffpills::app::parse_scene(
        diffpills::app::parse_json_line(input, "a JSON object with a field \"bodies\""));
  } catch (const std::invalid_argument&) {
    return;  // documented: a bad file is an error naming the field
  }
  std::vector<diffpills::Pose> poses(static_cast<std::size_t>(scene.size()));
  for (const diffpills::Contact& contact : scene.contacts(poses, 0.1)) {
    if (!std::isfinite(contact.distance) || !contact.gradient.allFinite()) {
      violated("a scene file's contacts are finite", input);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(bytes), size);

  std::vector<std::string> lines;
  std::istringstream splitter(input);
  for (std::string line; std::getline(splitter, line);) lines.push_back(line);

  std::istringstream in(input);
  std::ostringstream out;
  const int status = diffpills::app::run_query(in, out);

  std::vector<std::string> answers;
  std::istringstream answer_stream(out.str());
  for (std::string answer; std::getline(answer_stream, answer);) answers.push_back(answer);
  if (answers.size() != lines.size()) violated("one answer per line", out.str());

  bool any_error = false;
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const bool ok = check_answer(answers[i]);
    any_error = any_error || !ok;
    bool direct_ok = false;
    if (diffpills::app::answer_query_line(lines[i], direct_ok) != answers[i] || direct_ok != ok) {
      violated("answer_query_line agrees with the stream", answers[i]);
    }
  }
  if (status != (any_error ? 1 : 0)) violated("exit status", std::to_string(status));

  for (const std::string& line : lines) {
    bool ok = false;
    const std::string answer = diffpills::app::answer_scene_line(fixed_scene(), 0.1, line, ok);
    if (check_scene_answer(answer) != ok) violated("scene answer agrees with ok", answer);
  }
  if (size <= diffpills::app::kMaxLineBytes) check_scene_file(input);
  return 0;
}
