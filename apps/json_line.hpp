// One line of JSON text as `diffpills query` reads it (DESIGN.md section 3), whatever bytes the
// line holds: every problem becomes an error naming the field, never a crash.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace diffpills::app {

// A query nests 4 deep (the query, a shape, its "C", a row of C). Deeper lines are rejected while
// they are parsed, so nothing recursive (nlohmann copies, compares and dumps values recursively)
// ever walks a value deep enough to exhaust the stack; 64 leaves room for new fields.
constexpr std::size_t kMaxNesting = 64;

// Parses a line holding one JSON value. Objects are std::map based (nlohmann::json, not
// ordered_json) so that an object of n keys costs O(n log n) to build, not O(n^2). A UTF-8 byte
// order mark at the start of the line is skipped; CR, like any JSON whitespace, is ignored.
// Throws std::invalid_argument whose message starts with the field at fault ("a.r[1]: ...",
// "query: ..." when no field is) for a blank line ("query: empty line; expected <expected>"), a NUL
// byte, malformed JSON (the byte where the parser stopped and why, mentioning NaN and Infinity only
// when the line holds such a word), a number beyond the range of a double, a key given twice in one
// object, or nesting deeper than kMaxNesting arrays and objects.
nlohmann::json parse_json_line(const std::string& line, const std::string& expected);

}  // namespace diffpills::app
