// The JSON Lines loop the commands share (`diffpills query`, `diffpills scene`): one answer line
// per input line, in order, flushed as it is written, whatever bytes a line holds.
#pragma once

#include <cstddef>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

namespace diffpills::app {

// The exit statuses of the commands (documented in --help and in the README).
enum ExitStatus : int {
  kEveryLineAnswered = 0,
  kSomeLineAnError = 1,
  kMisuse = 2,
  kInputOutputFailed = 3,  // reading standard input or writing standard output failed
};

// Lines longer than this are answered with an error, and a command keeps only this much of one
// in memory. A polygon of 10^6 vertices in full-precision numbers is about 45 MB, so it fits,
// while what one line can cost stays bounded: parsed, a line of tiny arrays ([0,0],[0,0],...)
// takes about 22 times its length, 1.5 GB at this limit, and one of empty objects ([{},{},...])
// about 33 times, 2.1 GB (measured). Running out of memory is answered with an error line.
constexpr std::size_t kMaxLineBytes = std::size_t{64} << 20;

// What a command makes of one parsed line: its answer object. Throws std::invalid_argument (or
// any std::exception) whose message names the field at fault.
using Answer = std::function<nlohmann::ordered_json(const nlohmann::json&)>;

// An error message as the commands print it: cut at 1,000 bytes, and valid UTF-8 (bytes that are
// not are replaced by U+FFFD).
std::string error_text(std::string message);

// Answers one line: answer(the line parsed by parse_json_line) as one line of valid UTF-8 JSON, or
// {"error": "..."} (bytes that are not UTF-8 are replaced by U+FFFD where an error quotes them, and
// an error is cut at 1,000 bytes). expected says what the command reads on a line ("a JSON object
// with ..."), for the answer to a blank one. Sets ok to false for an error answer. Never throws.
std::string answer_line(const std::string& line, const std::string& expected, const Answer& answer,
                        bool& ok);

// Answers every line of `in` on `out`, in order, flushing each answer. Returns
// kEveryLineAnswered, or kSomeLineAnError if any line was answered with an error, or
// kInputOutputFailed (after saying why on `diagnostics`) as soon as a write to `out` fails or if
// reading `in` fails.
int run_lines(std::istream& in, std::ostream& out, std::ostream& diagnostics,
              const std::string& expected, const Answer& answer);

// Flushes `out`, standard output of the command. If this or an earlier write failed, says so on
// `diagnostics` ("diffpills: cannot write to standard output: <errno's reason>"; set errno to 0
// before writing for the reason to be this write's) and returns false.
bool flush_standard_output(std::ostream& out, std::ostream& diagnostics);

}  // namespace diffpills::app
