#pragma once
/// \file Validated access to JSON input files (scenes, materials). Every error is an InputError
/// whose `where` is "<file>: <path.to.field>" and whose message says what was expected and
/// what was found, e.g. `scene.json: material.young: expected a positive number, got -3`.
#include <elastolearn/core/types.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace elastolearn::io {

/// A view of a JSON object that knows its path ("scene.json: material.young") for error
/// messages. It refers to `value` without copying: the JSON must outlive the view.
class JsonObject {
  public:
  /// Throws InputError if `value` is not an object. `path` is the object's own field path
  /// ("" for the root, "material", "loads[2]").
  JsonObject(const nlohmann::json& value, std::string file, std::string path = "");

  /// True if `key` is present (even if null).
  bool has(const std::string& key) const;

  /// Required finite number.
  double number(const std::string& key) const;
  /// Optional finite number: `fallback` when absent.
  double number(const std::string& key, double fallback) const;
  /// Required number > 0.
  double positive(const std::string& key) const;
  /// Optional number > 0.
  double positive(const std::string& key, double fallback) const;
  /// Required integer (an integral JSON number within int range; 3.0 is accepted).
  int integer(const std::string& key) const;
  int integer(const std::string& key, int fallback) const;
  /// Optional true/false.
  bool boolean(const std::string& key, bool fallback) const;
  /// Required string.
  std::string string(const std::string& key) const;
  std::string string(const std::string& key, const std::string& fallback) const;
  /// Required array of exactly 3 finite numbers.
  Vec3 vec3(const std::string& key) const;
  Vec3 vec3(const std::string& key, const Vec3& fallback) const;
  /// Required array of finite numbers (may be empty); element errors name "key[i]".
  std::vector<double> numbers(const std::string& key) const;
  /// Required array of integers (may be empty).
  std::vector<int> integers(const std::string& key) const;
  /// Required nested object.
  JsonObject object(const std::string& key) const;
  /// Required array of objects; element i has path "key[i]".
  std::vector<JsonObject> objects(const std::string& key) const;
  /// Required string that is one of `choices`, else an error listing them.
  std::string choice(const std::string& key, const std::vector<std::string>& choices) const;
  /// Optional choice: `fallback` when absent.
  std::string choice(const std::string& key, const std::vector<std::string>& choices,
      const std::string& fallback) const;

  /// Unknown keys are errors (catches typos; suggests the nearest known key): call after
  /// reading, with every key you accept.
  void reject_unknown_keys(const std::vector<std::string>& known) const;

  /// "path.key" (or "key" at the root) for messages.
  std::string field(const std::string& key) const;
  /// Throws InputError("file: path.key", message). An empty key names the object itself.
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;

  const nlohmann::json& json() const { return *m_value; }
  const std::string& file() const { return m_file; }
  const std::string& path() const { return m_path; }

  private:
  /// The value at `key`; fails with "missing required field" if absent.
  const nlohmann::json& required(const std::string& key) const;
  const nlohmann::json* m_value;
  std::string m_file;
  std::string m_path;
};

/// A JSON value for messages: compact, cut to ~60 characters ("-3", "\"abc\"", "[1,2]", "null").
std::string describe_json(const nlohmann::json& value);

/// Parse a JSON file; syntax errors name the file, line and column ("scene.json:3:14"), and so
/// do numbers beyond double's range ("1e999") and nesting deeper than 256 arrays/objects (which
/// no elastolearn file needs, and which would exhaust the stack of recursive code).
/// Throws InputError.
nlohmann::json read_json_file(const std::filesystem::path& path);

/// Check "format": "<expected_kind>/<version>" with 1 ≤ version ≤ max_version and return the
/// version; errors name the file and say what was expected. Throws InputError.
int check_format(const JsonObject& root, const std::string& expected_kind, int max_version);

/// Write JSON atomically (pretty, 2-space indent, trailing newline). Throws InputError.
void write_json_file(const std::filesystem::path& path, const nlohmann::json& value);

} // namespace elastolearn::io
