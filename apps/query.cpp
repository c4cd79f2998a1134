#include "query.hpp"

#include <cerrno>
#include <cstring>
#include <istream>
#include <new>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>
#include <stdexcept>

#include "json_io.hpp"
#include "json_line.hpp"

namespace diffpills::app {
namespace {

using json = nlohmann::json;

// An error quoting a huge token or key is cut here: the field and the problem come first, and a
// message of megabytes helps nobody.
constexpr std::size_t kMaxErrorBytes = 1000;

// An optional true/false field, false when absent.
bool flag(const json& query, const char* key) {
  if (!query.contains(key)) return false;
  if (!query[key].is_boolean())
    throw std::invalid_argument(std::string(key) + ": must be true or false");
  return query[key].get<bool>();
}

nlohmann::ordered_json answer(const json& query) {
  if (!query.is_object()) {
    throw std::invalid_argument("query: must be a JSON object with fields \"a\" and \"b\"");
  }
  static const std::set<std::string> allowed = {"a", "b", "jacobian", "method", "signed_distance"};
  for (const auto& item : query.items()) {
    if (allowed.count(item.key()) == 0) {
      throw std::invalid_argument(item.key() + ": unknown field");
    }
  }
  for (const char* key : {"a", "b"}) {
    if (!query.contains(key)) throw std::invalid_argument(std::string(key) + ": missing");
  }
  const PosedShape a = parse_posed_shape(query["a"], "a");
  const PosedShape b = parse_posed_shape(query["b"], "b");
  const bool jacobian = flag(query, "jacobian");
  const bool signed_distance = flag(query, "signed_distance");
  ProximityOptions options;
  if (query.contains("method")) {
    const json& method = query["method"];
    if (method == "default") {
      options.method = Method::kDefault;
    } else if (method == "interior_point") {
      options.method = Method::kInteriorPoint;
    } else {
      throw std::invalid_argument("method: must be \"default\" or \"interior_point\"");
    }
  }
  nlohmann::ordered_json out =
      jacobian ? to_json(proximity_jacobian(a.shape, a.pose, b.shape, b.pose, options))
               : to_json(proximity(a.shape, a.pose, b.shape, b.pose, options));
  if (signed_distance) {  // (one method: "method" chooses the proximity's solver)
    out["signed_distance"] =
        jacobian ? to_json(signed_distance_jacobian(a.shape, a.pose, b.shape, b.pose))
                 : to_json(diffpills::signed_distance(a.shape, a.pose, b.shape, b.pose));
  }
  return out;
}

// One line of JSON in valid UTF-8: a message may quote bytes of the query that are not UTF-8
// (nlohmann's dump would throw on them), they become U+FFFD.
std::string to_line(const nlohmann::ordered_json& value) {
  return value.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

std::string error_answer(std::string message) {
  if (message.size() > kMaxErrorBytes) {
    message.resize(kMaxErrorBytes);
    message += " ...";
  }
  return to_line({{"error", std::move(message)}});
}

// Reads the next line of `in` without its '\n', like std::getline, but keeps at most
// kMaxLineBytes + 1 of its bytes and skips the rest: a line of any length costs bounded memory
// and is still answered (as too long). Returns false at the end of the input or when reading
// fails (then in.bad()).
bool read_line(std::istream& in, std::string& line) {
  line.clear();
  const std::istream::sentry sentry(in, /*noskipws=*/true);
  if (!sentry) return false;
  using traits = std::istream::traits_type;
  std::streambuf& buffer = *in.rdbuf();
  try {
    for (auto c = buffer.sbumpc();; c = buffer.sbumpc()) {
      if (traits::eq_int_type(c, traits::eof())) {
        in.setstate(std::ios::eofbit);
        return !line.empty();
      }
      if (traits::eq_int_type(c, traits::to_int_type('\n'))) return true;
      if (line.size() <= kMaxLineBytes) line.push_back(traits::to_char_type(c));
    }
  } catch (const std::ios_base::failure&) {  // libstdc++'s file buffers throw on a read error
    in.setstate(std::ios::badbit);
    return false;
  }
}

std::string errno_reason() { return errno == 0 ? "" : std::string(": ") + std::strerror(errno); }

}  // namespace

std::string answer_query_line(const std::string& line, bool& ok) {
  ok = false;
  try {
    if (line.size() > kMaxLineBytes) {
      throw std::invalid_argument("query: line longer than " + std::to_string(kMaxLineBytes) +
                                  " bytes");
    }
    std::string result = to_line(answer(parse_json_line(line)));
    ok = true;
    return result;
  } catch (const std::bad_alloc&) {
    return error_answer("query: not enough memory to parse this line (" +
                        std::to_string(line.size()) + " bytes)");
  } catch (const std::exception& error) {
    return error_answer(error.what());
  }
}

int run_query(std::istream& in, std::ostream& out, std::ostream& diagnostics) {
  int status = kEveryLineAnswered;
  std::string line;
  for (;;) {
    // errno is cleared before each read and write so that a failure's reason is its own.
    errno = 0;
    if (!read_line(in, line)) break;
    bool ok = false;
    const std::string answer_line = answer_query_line(line, ok);
    errno = 0;
    out << answer_line << '\n';
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
