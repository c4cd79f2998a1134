// libFuzzer target: arbitrary bytes as the standard input of `diffpills query` (issue 9).
//
// Checked: every line is answered by exactly one line, in order; every answer is valid JSON (in
// UTF-8, whatever bytes the query held), an object holding either "error" (a string) or a finite
// "phi"; the exit status says whether any line was an error. A single line is also answered
// directly by answer_query_line, which must agree with the stream's answer and never throw.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "query.hpp"

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
  return 0;
}
