#include "json_lines.hpp"

#include <cerrno>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "json_line.hpp"

namespace diffpills::app {
namespace {

// An error quoting a huge token or key is cut here: the field and the problem come first, and a
// message of megabytes helps nobody.
constexpr std::size_t kMaxErrorBytes = 1000;

// One line of JSON in valid UTF-8: a message may quote bytes of the query that are not UTF-8
// (nlohmann's dump would throw on them), they become U+FFFD.
std::string to_line(const nlohmann::ordered_json& value) {
  return value.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

// `message` cut at kMaxErrorBytes, with " ..." after the cut.
std::string cut(std::string message) {
  if (message.size() > kMaxErrorBytes) {
    message.resize(kMaxErrorBytes);
    message += " ...";
  }
  return message;
}

// to_line replaces the bytes that are not UTF-8 itself, so the message goes in as it is (through
// error_text, it was written, read back and written again: 3 passes of JSON instead of 1, and in
// fuzz_query, where most lines are errors, error_text was 17% of the time).
std::string error_answer(const std::string& message) { return to_line({{"error", cut(message)}}); }

// Reads the next line of `in` without its '\n', like std::getline, but keeps at most
// kMaxLineBytes + 1 of its bytes and skips the rest: a line of any length costs bounded memory
// and is still answered (as too long). If memory runs out while the line is kept, the rest of it
// is skipped too and `unread` is set (the line is answered with an error; a hostile review: a
// 60 MB line under ulimit -v ended the command). Returns false at the end of the input or when
// reading fails (then in.bad()).
bool read_line(std::istream& in, std::string& line, bool& unread) {
  line.clear();
  unread = false;
  const std::istream::sentry sentry(in, /*noskipws=*/true);
  if (!sentry) return false;
  using traits = std::istream::traits_type;
  std::streambuf& buffer = *in.rdbuf();
  try {
    for (auto c = buffer.sbumpc();; c = buffer.sbumpc()) {
      if (traits::eq_int_type(c, traits::eof())) {
        in.setstate(std::ios::eofbit);
        return !line.empty() || unread;
      }
      if (traits::eq_int_type(c, traits::to_int_type('\n'))) return true;
      if (unread || line.size() > kMaxLineBytes) continue;
      try {
        line.push_back(traits::to_char_type(c));
      } catch (const std::bad_alloc&) {
        std::string().swap(line);  // its memory back
        unread = true;
      }
    }
  } catch (const std::ios_base::failure&) {  // libstdc++'s file buffers throw on a read error
    in.setstate(std::ios::badbit);
    return false;
  }
}

std::string errno_reason() { return errno == 0 ? "" : std::string(": ") + std::strerror(errno); }

}  // namespace

std::string error_text(std::string message) {
  // nlohmann writes the bytes that are not UTF-8 as U+FFFD; reading its JSON string back gives
  // the text without the escapes.
  return nlohmann::json::parse(to_line(cut(std::move(message)))).get<std::string>();
}

std::string answer_line(const std::string& line, const std::string& expected, const Answer& answer,
                        bool& ok) {
  ok = false;
  try {
    if (line.size() > kMaxLineBytes) {
      throw std::invalid_argument("query: line longer than " + std::to_string(kMaxLineBytes) +
                                  " bytes");
    }
    // Both values released, not destroyed, however this ends (json_line.hpp's release): a line
    // or an answer of millions of entries would otherwise allocate as it goes.
    const Released<nlohmann::json> query(parse_json_line(line, expected));
    const Released<nlohmann::ordered_json> result(answer(query.value));
    std::string text = to_line(result.value);
    ok = true;
    return text;
  } catch (const std::bad_alloc&) {
    return error_answer("query: not enough memory to parse this line (" +
                        std::to_string(line.size()) + " bytes)");
  } catch (const std::exception& error) {
    return error_answer(error.what());
  }
}

int run_lines(std::istream& in, std::ostream& out, std::ostream& diagnostics,
              const std::string& expected, const Answer& answer) {
  int status = kEveryLineAnswered;
  std::string line;
  for (;;) {
    // errno is cleared before each read and write so that a failure's reason is its own.
    errno = 0;
    bool unread = false;
    if (!read_line(in, line, unread)) break;
    bool ok = false;
    const std::string answer_text = unread
                                        ? error_answer("query: not enough memory to read this line")
                                        : answer_line(line, expected, answer, ok);
    errno = 0;
    out << answer_text << '\n';
    if (!flush_standard_output(out, diagnostics)) return kInputOutputFailed;
    if (!ok) status = kSomeLineAnError;
  }
  if (in.bad()) {
    diagnostics << "diffpills: cannot read standard input" << errno_reason() << "\n";
    return kInputOutputFailed;
  }
  return status;
}

bool flush_standard_output(std::ostream& out, std::ostream& diagnostics) {
  out.flush();
  if (out) return true;
  diagnostics << "diffpills: cannot write to standard output" << errno_reason() << "\n";
  return false;
}

}  // namespace diffpills::app
