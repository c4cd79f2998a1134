// One line of JSON text as `diffpills query` reads it (DESIGN.md section 3), whatever bytes the
// line holds: every problem becomes an error naming the field, never a crash.
#pragma once

#include <cstddef>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

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
// ulimit -v, every later line lost). Here each container is emptied from its last child, each
// child released first, so every destructor run meets empty containers; the commands' values nest
// at most kMaxNesting deep, so the recursion is bounded.
template <class Json>
void release(Json& value) noexcept {
  if (value.is_array()) {
    auto& items = value.template get_ref<typename Json::array_t&>();
    while (!items.empty()) {
      release(items.back());
      items.pop_back();
    }
  } else if (value.is_object()) {
    auto& members = value.template get_ref<typename Json::object_t&>();
    while (!members.empty()) {
      const auto last = std::prev(members.end());
      release(last->second);
      members.erase(last);
    }
  }
}

// A value released (above) when it goes out of scope, by any path.
template <class Json>
struct Released {
  Released() = default;
  explicit Released(Json&& json) : value(std::move(json)) {}
  Released(const Released&) = delete;
  Released& operator=(const Released&) = delete;
  ~Released() { release(value); }
  Json value;
};

}  // namespace diffpills::app
