// `diffpills query`: JSON Lines in, JSON Lines out (DESIGN.md section 3).
#pragma once

#include <iostream>
#include <string>

#include "json_lines.hpp"

namespace diffpills::app {

// Answers one query line: the result object, or {"error": "..."} naming the field at fault. The
// answer is one line of valid UTF-8 JSON whatever bytes the query held (bytes that are not UTF-8
// are replaced by U+FFFD where an error quotes them). Sets ok to false for an error answer.
// Never throws.
std::string answer_query_line(const std::string& line, bool& ok);

// Answers every line of `in` on `out`, in order, flushing each answer. Returns
// kEveryLineAnswered, or kSomeLineAnError if any line was answered with an error, or
// kInputOutputFailed (after saying why on `diagnostics`) as soon as a write to `out` fails or if
// reading `in` fails.
int run_query(std::istream& in, std::ostream& out, std::ostream& diagnostics = std::cerr);

}  // namespace diffpills::app
