// `diffpills query`: JSON Lines in, JSON Lines out (DESIGN.md section 3).
#pragma once

#include <iosfwd>
#include <string>

namespace diffpills::app {

// Answers one query line: the result object, or {"error": "..."} naming the field at fault.
// Sets ok to false for an error answer. Never throws.
std::string answer_query_line(const std::string& line, bool& ok);

// Answers every line of `in` on `out`, in order. Returns 0 if every line was answered with a
// result, 1 if any line was answered with an error.
int run_query(std::istream& in, std::ostream& out);

}  // namespace diffpills::app
