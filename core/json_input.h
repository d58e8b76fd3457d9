// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading JSON input files so that every complaint names the file and the JSON path of the value at fault,
// e.g. "box.json: materials.red_plastic.roughness: must be in [0, 1], got 1.5".
//
// Documents are nlohmann::ordered_json, which keeps the author's key order: validation then reports the
// first problem in reading order, and an embedded copy of the document reads like the file.

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace ct {

using Json = nlohmann::ordered_json;

// How every document is written (Json::dump's error handler): text from file names and headers that is not UTF-8
// (Linux allows any bytes in a name) has each invalid byte as U+FFFD, where the default would end the run.
inline constexpr auto kReplaceInvalidUtf8 = nlohmann::ordered_json::error_handler_t::replace;

// Parses JSON text. A syntax error is an InputError "source: line L, column C: <reason>"; a key repeated in
// one object is an InputError naming its JSON path (JSON parsers would silently keep one of the two).
Json parse_json(std::string_view text, const std::string& source);
// Reads and parses a file; errors name the path as given.
Json read_json(const std::filesystem::path& file);

// A value inside a JSON document together with where it is, for reading it with checks. It refers to the
// document, which must outlive it. Every check failure throws InputError("<source>: <path>: <message>").
class JsonNode {
 public:
  JsonNode(const Json& value, std::string source) : value_(&value), source_(std::move(source)) {}

  const Json& json() const { return *value_; }
  const std::string& source() const { return source_; }
  // "materials.wall.reflectance", "objects[3]"; empty at the root.
  const std::string& path() const { return path_; }
  // "<source>: <path>", the prefix of this node's messages (for errors raised by other readers).
  std::string location() const;
  [[noreturn]] void fail(std::string_view message) const;

  // Objects. expect_object checks the type and that every key is one of `allowed` (a typo must not be
  // silently ignored); the message for an unknown key names the key's own path and lists the allowed ones.
  void expect_object(std::initializer_list<std::string_view> allowed) const;
  bool has(std::string_view key) const;
  JsonNode operator[](std::string_view key) const;                // the key must be present
  std::optional<JsonNode> find(std::string_view key) const;       // absent -> nullopt
  std::vector<std::pair<std::string, JsonNode>> members() const;  // in file order; must be an object

  // Arrays.
  std::vector<JsonNode> elements() const;  // must be an array

  // Scalars: each checks the JSON type (and that numbers are finite).
  double number() const;
  double number_in(double lo, double hi) const;  // lo <= x <= hi
  double number_above(double lo) const;          // x > lo
  double number_at_least(double lo) const;       // x >= lo
  std::int64_t integer() const;                  // a number with no fractional part
  std::int64_t integer_in(std::int64_t lo, std::int64_t hi) const;
  bool boolean() const;
  std::string string() const;
  std::string non_empty_string() const;
  // A string that must be one of `choices`.
  std::string choice(std::initializer_list<std::string_view> choices) const;
  // An array of exactly 3 numbers.
  Eigen::Vector3d vec3() const;

 private:
  JsonNode(const Json& value, std::string source, std::string path)
      : value_(&value), source_(std::move(source)), path_(std::move(path)) {}
  JsonNode child(std::string_view key) const;
  [[noreturn]] void fail_type(std::string_view expected) const;

  const Json* value_;
  std::string source_;
  std::string path_;
};

// A short description of a JSON value for messages: `string "abc"`, `number -0.2`, `an object`.
std::string describe_json(const Json& value);

}  // namespace ct
