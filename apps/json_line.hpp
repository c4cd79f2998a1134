// One line of JSON text as `diffpills query` reads it (DESIGN.md section 3), whatever bytes the
// line holds: every problem becomes an error naming the field, never a crash.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace diffpills::app {

// A query line nests 4 deep (the query, a shape, its "C", a row of C), a scene line 4 (the line,
// "poses", a body's pose, its "r") and a scene file 7 (down to a row of a polygon's "C"). Deeper
// input is rejected while it is parsed, so nothing recursive (nlohmann copies, compares and dumps
// values recursively) ever walks a value deep enough to exhaust the stack; 64 leaves room for new
// fields.
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

// A key or a name from the input as an error message shows it: JSON-escaped without the quotes
// (control characters as \u00XX, bytes that are not UTF-8 replaced), so that a plain key stays as
// it is. A NUL byte, which "\u0000" in a key decodes to, would otherwise end the message where it
// is read back through what() as a C string: {"a\u0000": 1} was answered {"error":"a"}, the
// message lost and the field misnamed (a hostile review).
std::string key_text(const std::string& key);

// Empties `value` without allocating, so that destroying it allocates nothing either. nlohmann's
// destructor first moves a non-empty container's children into a new vector (to free deep values
// without recursion), and that allocation fails where memory ran out, inside a destructor: a
// std::bad_alloc there ends the program (a hostile review: a line of 4 million numbers under
// ulimit -v, every later line lost). Here each child of a container is released in place, then
// the container is cleared, so every destructor run meets an empty container (whose flattening
// reserves nothing) or a scalar; the commands' values nest at most kMaxNesting deep, so the
// recursion is bounded. Nothing here can throw: get_ptr gives a null pointer for another type
// (get_ref would throw), and clear() is noexcept (an ordered_map's erase is not).
template <class Json>
void release(Json& value) noexcept {
  if (auto* items = value.template get_ptr<typename Json::array_t*>()) {
    for (Json& item : *items) release(item);
    items->clear();
  } else if (auto* members = value.template get_ptr<typename Json::object_t*>()) {
    for (auto& member : *members) release(member.second);
    members->clear();
  }
}

// A value released (above) when it goes out of scope, by any path.
template <class Json>
struct Released {
  // nlohmann's default constructor is noexcept and makes a null (no allocation) by delegating to
  // basic_json(value_t), which can throw for other types; the check follows that call.
  Released() = default;  // NOLINT(bugprone-exception-escape)
  explicit Released(Json&& json) : value(std::move(json)) {}
  Released(const Released&) = delete;
  Released& operator=(const Released&) = delete;
  ~Released() { release(value); }
  Json value;
};

}  // namespace diffpills::app
