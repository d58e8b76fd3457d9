// SPDX-License-Identifier: Apache-2.0
#include "core/json_input.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/error.h"
#include "core/file_io.h"

namespace ct {
namespace {

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : fmt::format("{}.{}", parent, key);
}

std::string element_path(const std::string& parent, std::size_t index) { return fmt::format("{}[{}]", parent, index); }

std::string quoted_list(std::initializer_list<std::string_view> items) {
  std::string text;
  for (std::string_view item : items) text += fmt::format("{}\"{}\"", text.empty() ? "" : ", ", item);
  return text;
}

// Tracks where the parser is (object keys and array indices) so that a repeated key, or a value the parser
// refuses, can be reported by its JSON path; nlohmann's parser callback reports structure events but not
// positions. The parser copies its callback: this is the state, the callback refers to it.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(std::string source) : source_(std::move(source)) {}

  // The JSON path of the value being parsed: after a key, the key's; in an array, the next element's.
  std::string current_path() const {
    std::string path;
    for (const Frame& frame : frames_)
      path = frame.array ? element_path(path, frame.index) : child_path(path, frame.key);
    return path;
  }

  bool operator()(int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start: frames_.push_back({false, 0, {}, {}}); break;
      case Json::parse_event_t::array_start: frames_.push_back({true, 0, {}, {}}); break;
      case Json::parse_event_t::key: {
        Frame& frame = frames_.back();
        frame.key = parsed.get<std::string>();
        if (!frame.keys.insert(frame.key).second)
          throw InputError(fmt::format("{}: {}: key appears twice in one object", source_, current_path()));
        break;
      }
      case Json::parse_event_t::value: next_element(); break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        frames_.pop_back();
        next_element();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;
    std::string key;
    std::set<std::string> keys;
  };

  void next_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  std::string source_;
  std::vector<Frame> frames_;
};

// Where nlohmann's parser stopped: it tells a SAX handler the byte offset of an error, but leaves it out of
// the exceptions of its DOM parser for values it refuses (a number beyond the range of a double).
class ErrorOffset final : public nlohmann::json_sax<Json> {
 public:
  std::optional<std::size_t> offset;
  std::string token;

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception&) override {
    offset = position;
    token = last_token;
    return false;
  }
};

// "line L, column C" of the start of the token the parser refused, or "" if it cannot be found.
std::string error_position(std::string_view text) {
  ErrorOffset handler;
  try {
    Json::sax_parse(text.begin(), text.end(), &handler);
  } catch (const std::exception&) {
    return "";
  }
  if (!handler.offset || *handler.offset > text.size()) return "";
  const std::size_t start = *handler.offset >= handler.token.size() ? *handler.offset - handler.token.size() : 0;
  const std::string_view before = text.substr(0, start);
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
  const std::size_t line_start = before.rfind('\n');
  const std::size_t column = line_start == std::string_view::npos ? start + 1 : start - line_start;
  return fmt::format("line {}, column {}: ", line, column);
}

// nlohmann's message without its "[json.exception.out_of_range.406] " prefix.
std::string without_prefix(const std::string& what) {
  if (!what.starts_with("[json.exception.")) return what;
  const std::size_t end = what.find("] ");
  return end == std::string::npos ? what : what.substr(end + 2);
}

}  // namespace

Json parse_json(std::string_view text, const std::string& source) {
  DuplicateKeyCheck where(source);
  try {
    return Json::parse(text.begin(), text.end(),
                       [&where](int depth, Json::parse_event_t event, Json& parsed) { return where(depth, event, parsed); });
  } catch (const Json::out_of_range& e) {
    // 406: a number the parser read but that no double holds, e.g. 1e999.
    const std::string path = where.current_path();
    std::string reason = without_prefix(e.what());
    if (e.id == 406) {
      const std::size_t first = reason.find('\''), last = reason.rfind('\'');
      std::string number = first < last ? reason.substr(first + 1, last - first - 1) : "";
      if (number.size() > 40) number = number.substr(0, 40) + "...";  // a 400-digit integer, say
      reason = fmt::format("number {} is out of range (a finite number of magnitude below 1.8e308 is needed)", number);
    }
    throw InputError(fmt::format("{}: {}{}{}", source, error_position(text), path.empty() ? "" : path + ": ", reason));
  } catch (const Json::parse_error& e) {
    // nlohmann says "[json.exception.parse_error.101] parse error at line 3, column 14: <reason>"; keep
    // the position and the reason.
    const std::string what = e.what();
    const std::string marker = "parse error at ";
    const std::size_t at = what.find(marker);
    throw InputError(fmt::format("{}: {}", source, at == std::string::npos ? what : what.substr(at + marker.size())));
  } catch (const Json::exception& e) {
    throw InputError(fmt::format("{}: {}", source, without_prefix(e.what())));
  }
}

Json read_json(const std::filesystem::path& file) { return parse_json(read_file(file), file.string()); }

std::string describe_json(const Json& value) {
  constexpr std::size_t kMaxShown = 40;
  switch (value.type()) {
    case Json::value_t::string: {
      std::string s = value.get<std::string>();
      if (s.size() > kMaxShown) s = s.substr(0, kMaxShown) + "...";
      return fmt::format("string \"{}\"", s);
    }
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return fmt::format("number {}", value.dump());
    case Json::value_t::boolean: return value.get<bool>() ? "true" : "false";
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    default: return value.type_name();
  }
}

std::string JsonNode::location() const { return path_.empty() ? source_ : fmt::format("{}: {}", source_, path_); }

void JsonNode::fail(std::string_view message) const { throw InputError(fmt::format("{}: {}", location(), message)); }

void JsonNode::fail_type(std::string_view expected) const {
  fail(fmt::format("must be {}, got {}", expected, describe_json(*value_)));
}

JsonNode JsonNode::child(std::string_view key) const {
  return JsonNode(value_->find(key).value(), source_, child_path(path_, key));
}

void JsonNode::expect_object(std::initializer_list<std::string_view> allowed) const {
  if (!value_->is_object()) fail_type("an object");
  for (const auto& [key, value] : value_->items()) {
    bool known = false;
    for (std::string_view name : allowed) known = known || name == key;
    if (!known) child(key).fail(fmt::format("unknown key (allowed: {})", quoted_list(allowed)));
  }
}

bool JsonNode::has(std::string_view key) const { return value_->is_object() && value_->contains(key); }

JsonNode JsonNode::operator[](std::string_view key) const {
  if (!value_->is_object()) fail_type("an object");
  if (!value_->contains(key)) fail(fmt::format("missing key \"{}\"", key));
  return child(key);
}

std::optional<JsonNode> JsonNode::find(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  return child(key);
}

std::vector<std::pair<std::string, JsonNode>> JsonNode::members() const {
  if (!value_->is_object()) fail_type("an object");
  std::vector<std::pair<std::string, JsonNode>> result;
  for (const auto& [key, value] : value_->items()) result.emplace_back(key, child(key));
  return result;
}

std::vector<JsonNode> JsonNode::elements() const {
  if (!value_->is_array()) fail_type("an array");
  std::vector<JsonNode> result;
  for (std::size_t i = 0; i < value_->size(); ++i)
    result.push_back(JsonNode((*value_)[i], source_, element_path(path_, i)));
  return result;
}

double JsonNode::number() const {
  if (!value_->is_number()) fail_type("a number");
  const double x = value_->get<double>();
  if (!std::isfinite(x)) fail(fmt::format("must be a finite number, got {}", value_->dump()));
  return x;
}

double JsonNode::number_in(double lo, double hi) const {
  const double x = number();
  if (!(x >= lo && x <= hi)) fail(fmt::format("must be in [{}, {}], got {}", lo, hi, x));
  return x;
}

double JsonNode::number_above(double lo) const {
  const double x = number();
  if (!(x > lo)) fail(fmt::format("must be > {}, got {}", lo, x));
  return x;
}

double JsonNode::number_at_least(double lo) const {
  const double x = number();
  if (!(x >= lo)) fail(fmt::format("must be >= {}, got {}", lo, x));
  return x;
}

std::int64_t JsonNode::integer() const {
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (value_->is_number_unsigned()) {
    if (value_->get<std::uint64_t>() <= kMax) return value_->get<std::int64_t>();
  } else if (value_->is_number_integer()) {
    return value_->get<std::int64_t>();
  } else if (value_->is_number_float()) {
    // 256.0 is accepted as 256: some writers emit every number as a float.
    const double x = value_->get<double>();
    if (x == std::floor(x) && std::abs(x) < 9.0e15) return static_cast<std::int64_t>(x);
  }
  fail_type("a whole number");
}

std::int64_t JsonNode::integer_in(std::int64_t lo, std::int64_t hi) const {
  const std::int64_t n = integer();
  if (n < lo) fail(fmt::format("must be >= {}, got {}", lo, n));
  if (n > hi) fail(fmt::format("must be <= {}, got {}", hi, n));
  return n;
}

bool JsonNode::boolean() const {
  if (!value_->is_boolean()) fail_type("true or false");
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (!value_->is_string()) fail_type("a string");
  return value_->get<std::string>();
}

std::string JsonNode::non_empty_string() const {
  std::string s = string();
  if (s.empty()) fail("must not be empty");
  return s;
}

std::string JsonNode::choice(std::initializer_list<std::string_view> choices) const {
  std::string s = string();
  for (std::string_view c : choices)
    if (c == s) return s;
  fail(fmt::format("must be one of {}, got \"{}\"", quoted_list(choices), s));
}

Eigen::Vector3d JsonNode::vec3() const {
  if (!value_->is_array() || value_->size() != 3) fail_type("an array of 3 numbers [x, y, z]");
  const std::vector<JsonNode> xyz = elements();
  return {xyz[0].number(), xyz[1].number(), xyz[2].number()};
}

}  // namespace ct
