#include "json_line.hpp"

#include <cctype>
#include <stdexcept>
#include <utility>
#include <vector>

namespace diffpills::app {
namespace {

using json = nlohmann::json;

constexpr const char* kByteOrderMark = "\xEF\xBB\xBF";

// Whether `line` holds, outside strings, a word that a user may mean as a number but JSON has no
// such number for: NaN, Infinity or inf, in any case, signed or not.
bool holds_non_finite_word(const std::string& line) {
  bool in_string = false;
  std::string word;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    const char c = i < line.size() ? line[i] : ' ';  // a space ends a word at the end of the line
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character cannot end the string
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) != 0) {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      continue;
    }
    if (word == "nan" || word == "inf" || word == "infinity") return true;
    word.clear();
    in_string = c == '"';
  }
  return false;
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at line 1, column
// 7: " prefix: the id means nothing to a user, the line is always 1, and the position is reported
// as a byte of the line by the caller.
std::string parser_reason(const json::exception& error) {
  std::string text = error.what();
  const std::size_t id_end = text.find("] ");
  if (text.rfind("[json.exception.", 0) == 0 && id_end != std::string::npos) {
    text.erase(0, id_end + 2);
  }
  const std::size_t position_end = text.find(": ");
  if (text.rfind("parse error at ", 0) == 0 && position_end != std::string::npos) {
    text.erase(0, position_end + 2);
  }
  return text;
}

// nlohmann's SAX interface: builds the value like nlohmann's own DOM builder, and knows at every
// event which field it is in, so that an error names it. Stops at nesting deeper than kMaxNesting
// and at a key given twice (nlohmann would silently keep the last one).
class LineBuilder {
 public:
  LineBuilder(const std::string& line, json& root) : line_(line), root_(root) {}

  bool null() { return add(nullptr); }
  bool boolean(bool value) { return add(value); }
  bool number_integer(json::number_integer_t value) { return add(value); }
  bool number_unsigned(json::number_unsigned_t value) { return add(value); }
  bool number_float(json::number_float_t value, const json::string_t& /*text*/) {
    return add(value);
  }
  bool string(json::string_t& value) { return add(std::move(value)); }
  // Required by the interface, called for binary formats only: JSON text never produces one.
  bool binary(json::binary_t& /*value*/) { return false; }
  bool start_object(std::size_t /*size*/) { return open(json::object()); }
  bool start_array(std::size_t /*size*/) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(json::string_t& name) {
    Level& object = levels_.back();
    object.key = name;
    object.member_open = true;
    if (object.container->contains(name)) return fail("given twice in one object");
    return true;
  }

  bool parse_error(std::size_t position, const std::string& /*last_token*/,
                   const json::exception& error) {
    // 406: a number JSON allows but a double cannot hold (1e999), the one way a non-finite
    // number can arrive; NaN and Infinity are not JSON, so they are syntax errors.
    const bool non_finite = error.id == 406 || holds_non_finite_word(line_);
    return fail("malformed JSON at byte " + std::to_string(position) + ": " + parser_reason(error) +
                (non_finite ? " (numbers must be finite: NaN and Infinity are not JSON, and a "
                              "double holds at most about 1.8e308)"
                            : ""));
  }

  const std::string& error() const { return error_; }

 private:
  // An open array or object. For an object, `key` names the member being parsed while
  // `member_open`; for an array, `index` counts the elements already complete.
  struct Level {
    explicit Level(json* opened) : container(opened) {}
    json* container;
    std::string key;
    bool member_open = false;
    std::size_t index = 0;
  };

  // The field being parsed, e.g. "a.C[3]"; "query" for the line as a whole.
  std::string path() const {
    std::string out;
    for (const Level& level : levels_) {
      if (level.container->is_array()) {
        out += "[" + std::to_string(level.index) + "]";
      } else if (level.member_open) {
        out += (out.empty() ? "" : ".") + key_text(level.key);
      }
    }
    return out.empty() || out[0] == '[' ? "query" + out : out;
  }

  bool fail(const std::string& problem) {
    error_ = path() + ": " + problem;
    return false;  // stops the parser
  }

  // Stores `value` where the parser is: the root, the next element, or the open member.
  json* place(json&& value) {
    if (levels_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Level& level = levels_.back();
    if (level.container->is_array()) {
      level.container->push_back(std::move(value));
      return &level.container->back();
    }
    return &((*level.container)[level.key] = std::move(value));
  }

  void complete_member() {
    if (levels_.empty()) return;
    Level& level = levels_.back();
    if (level.container->is_array()) {
      ++level.index;
    } else {
      level.member_open = false;
    }
  }

  bool add(json&& value) {
    place(std::move(value));
    complete_member();
    return true;
  }

  bool open(json&& container) {
    if (levels_.size() >= kMaxNesting) {
      return fail("arrays and objects nested deeper than " + std::to_string(kMaxNesting) +
                  " levels");
    }
    levels_.emplace_back(place(std::move(container)));
    return true;
  }

  bool close() {
    levels_.pop_back();
    complete_member();
    return true;
  }

  const std::string& line_;
  json& root_;
  std::vector<Level> levels_;
  std::string error_;
};

}  // namespace

json parse_json_line(const std::string& line, const std::string& expected) {
  const std::size_t text_start = line.rfind(kByteOrderMark, 0) == 0 ? 3 : 0;
  if (line.find_first_not_of(" \t\r\n", text_start) == std::string::npos) {
    throw std::invalid_argument("query: empty line; expected " + expected);
  }
  // nlohmann takes a NUL byte for the end of the text and would ignore what follows it.
  const std::size_t nul = line.find('\0');
  if (nul != std::string::npos) {
    throw std::invalid_argument("query: malformed JSON at byte " + std::to_string(nul + 1) +
                                ": a NUL byte (JSON text cannot hold one; in a string, write "
                                "\\u0000)");
  }
  // A line refused part way (malformed, or memory running out) is released, not destroyed.
  Released<json> root;
  LineBuilder builder(line, root.value);
  // nlohmann skips the byte order mark itself, so byte positions count it.
  if (!json::sax_parse(line, &builder)) throw std::invalid_argument(builder.error());
  return std::move(root.value);
}

std::string key_text(const std::string& key) {
  const std::string quoted = json(key).dump(-1, ' ', false, json::error_handler_t::replace);
  return quoted.substr(1, quoted.size() - 2);
}

}  // namespace diffpills::app
