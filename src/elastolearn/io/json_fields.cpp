#include <elastolearn/core/atomic_file.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/json_fields.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <optional>

namespace elastolearn::io {

using Json = nlohmann::json;

namespace {

std::string quoted_list(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i)
    s += (i ? ", \"" : "\"") + items[i] + "\"";
  return s;
}

/// Levenshtein distance, for "did you mean" suggestions.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({ row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1]) });
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// The value as an int if it is an integral number in int range.
std::optional<int> as_int(const Json& value) {
  if (value.is_number_unsigned()) {
    const auto v = value.get<std::uint64_t>();
    if (v <= std::uint64_t(INT_MAX))
      return int(v);
    return std::nullopt;
  }
  if (value.is_number_integer()) {
    const auto v = value.get<std::int64_t>();
    if (v >= INT_MIN && v <= INT_MAX)
      return int(v);
    return std::nullopt;
  }
  if (value.is_number_float()) {
    const double v = value.get<double>();
    if (std::isfinite(v) && v == std::floor(v) && v >= INT_MIN && v <= INT_MAX)
      return int(v);
  }
  return std::nullopt;
}

bool is_finite_number(const Json& value) {
  return value.is_number() && std::isfinite(value.get<double>());
}

} // namespace

std::string describe_json(const Json& value) {
  std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
  if (text.size() > 60)
    text = text.substr(0, 57) + "...";
  return text;
}

JsonObject::JsonObject(const Json& value, std::string file, std::string path)
    : m_value(&value)
    , m_file(std::move(file))
    , m_path(std::move(path)) {
  if (!value.is_object())
    fail("", "expected an object, got " + describe_json(value));
}

std::string JsonObject::field(const std::string& key) const {
  return m_path.empty() ? key : key.empty() ? m_path : m_path + "." + key;
}

void JsonObject::fail(const std::string& key, const std::string& message) const {
  const std::string name = field(key);
  throw InputError(name.empty() ? m_file : m_file + ": " + name, message);
}

bool JsonObject::has(const std::string& key) const {
  return m_value->contains(key);
}

const Json& JsonObject::required(const std::string& key) const {
  const auto it = m_value->find(key);
  if (it == m_value->end())
    fail(key, "missing required field");
  return *it;
}

double JsonObject::number(const std::string& key) const {
  const Json& v = required(key);
  if (!v.is_number())
    fail(key, "expected a number, got " + describe_json(v));
  if (!is_finite_number(v))
    fail(key, "expected a finite number, got " + describe_json(v));
  return v.get<double>();
}

double JsonObject::number(const std::string& key, double fallback) const {
  return has(key) ? number(key) : fallback;
}

double JsonObject::positive(const std::string& key) const {
  const Json& v = required(key);
  if (!is_finite_number(v) || !(v.get<double>() > 0)) {
    fail(key, "expected a positive number, got " + describe_json(v));
  }
  return v.get<double>();
}

double JsonObject::positive(const std::string& key, double fallback) const {
  return has(key) ? positive(key) : fallback;
}

int JsonObject::integer(const std::string& key) const {
  const Json& v = required(key);
  const std::optional<int> i = as_int(v);
  if (!i)
    fail(key, "expected an integer, got " + describe_json(v));
  return *i;
}

int JsonObject::integer(const std::string& key, int fallback) const {
  return has(key) ? integer(key) : fallback;
}

bool JsonObject::boolean(const std::string& key, bool fallback) const {
  if (!has(key))
    return fallback;
  const Json& v = required(key);
  if (!v.is_boolean())
    fail(key, "expected true or false, got " + describe_json(v));
  return v.get<bool>();
}

std::string JsonObject::string(const std::string& key) const {
  const Json& v = required(key);
  if (!v.is_string())
    fail(key, "expected a string, got " + describe_json(v));
  return v.get<std::string>();
}

std::string JsonObject::string(const std::string& key, const std::string& fallback) const {
  return has(key) ? string(key) : fallback;
}

Vec3 JsonObject::vec3(const std::string& key) const {
  const Json& v = required(key);
  const bool ok = v.is_array() && v.size() == 3
      && std::all_of(v.begin(), v.end(), [](const Json& e) { return is_finite_number(e); });
  if (!ok)
    fail(key, "expected an array of 3 finite numbers, got " + describe_json(v));
  return { v[0].get<double>(), v[1].get<double>(), v[2].get<double>() };
}

Vec3 JsonObject::vec3(const std::string& key, const Vec3& fallback) const {
  return has(key) ? vec3(key) : fallback;
}

std::vector<double> JsonObject::numbers(const std::string& key) const {
  const Json& v = required(key);
  if (!v.is_array())
    fail(key, "expected an array of numbers, got " + describe_json(v));
  std::vector<double> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!is_finite_number(v[i])) {
      fail(key + "[" + std::to_string(i) + "]",
          "expected a finite number, got " + describe_json(v[i]));
    }
    out.push_back(v[i].get<double>());
  }
  return out;
}

std::vector<int> JsonObject::integers(const std::string& key) const {
  const Json& v = required(key);
  if (!v.is_array())
    fail(key, "expected an array of integers, got " + describe_json(v));
  std::vector<int> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::optional<int> e = as_int(v[i]);
    if (!e)
      fail(key + "[" + std::to_string(i) + "]", "expected an integer, got " + describe_json(v[i]));
    out.push_back(*e);
  }
  return out;
}

JsonObject JsonObject::object(const std::string& key) const {
  return JsonObject(required(key), m_file, field(key));
}

std::vector<JsonObject> JsonObject::objects(const std::string& key) const {
  const Json& v = required(key);
  if (!v.is_array())
    fail(key, "expected an array of objects, got " + describe_json(v));
  std::vector<JsonObject> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    out.emplace_back(v[i], m_file, field(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

std::string JsonObject::choice(
    const std::string& key, const std::vector<std::string>& choices) const {
  const Json& v = required(key);
  if (v.is_string()
      && std::find(choices.begin(), choices.end(), v.get<std::string>()) != choices.end()) {
    return v.get<std::string>();
  }
  fail(key, "expected one of " + quoted_list(choices) + ", got " + describe_json(v));
}

std::string JsonObject::choice(const std::string& key, const std::vector<std::string>& choices,
    const std::string& fallback) const {
  return has(key) ? choice(key, choices) : fallback;
}

void JsonObject::reject_unknown_keys(const std::vector<std::string>& known) const {
  for (const auto& [key, value] : m_value->items()) {
    if (std::find(known.begin(), known.end(), key) != known.end())
      continue;
    const std::string* best = nullptr;
    std::size_t best_distance = std::max<std::size_t>(2, key.size() / 3) + 1;
    for (const std::string& k : known) {
      const std::size_t d = edit_distance(key, k);
      if (d < best_distance)
        best = &k, best_distance = d;
    }
    if (best)
      fail(key, "unknown field (did you mean \"" + *best + "\"?)");
    fail(key,
        known.empty() ? std::string("unknown field (no fields are accepted here)")
                      : "unknown field (expected one of " + quoted_list(known) + ")");
  }
}

namespace {

/// "file:line:column" of byte `offset` (0-based) of `text`.
std::string text_position(
    const std::filesystem::path& path, const std::string& text, std::size_t offset) {
  const std::size_t end = std::min(offset, text.size());
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return path.string() + ":" + std::to_string(line) + ":" + std::to_string(column);
}

/// The deepest nesting of arrays and objects we parse. nlohmann's parser keeps its own stack, but
/// other code walks values recursively: 10⁵ '[' would overflow the call stack. Files of this
/// library nest a few levels.
constexpr int k_max_json_depth = 256;

/// Throws InputError at the first '[' or '{' (outside strings) nested deeper than the limit.
void check_json_depth(const std::filesystem::path& path, const std::string& text) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > k_max_json_depth)
        throw InputError(text_position(path, text, i),
            "invalid JSON: nested deeper than " + std::to_string(k_max_json_depth) + " levels");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

} // namespace

Json read_json_file(const std::filesystem::path& path) {
  const std::string text = read_text_file(path);
  check_json_depth(path, text);
  try {
    return Json::parse(text);
  } catch (const Json::out_of_range& e) {
    // A number beyond double's range ("1e999"): the message quotes it; point at it if found.
    std::string message = e.what();
    const std::size_t colon = message.find("] ");
    if (colon != std::string::npos)
      message = message.substr(colon + 2);
    const std::size_t quote = message.find('\'');
    const std::size_t end = quote == std::string::npos ? quote : message.find('\'', quote + 1);
    const std::size_t at = end == std::string::npos
        ? std::string::npos
        : text.find(message.substr(quote + 1, end - quote - 1));
    throw InputError(at == std::string::npos ? path.string() : text_position(path, text, at),
        "invalid JSON: " + message);
  } catch (const Json::parse_error& e) {
    // Where parsing stopped (e.byte is 1-based).
    const std::string where = text_position(path, text, e.byte ? e.byte - 1 : 0);
    std::string message = e.what();
    const std::size_t at = message.find("column ");
    const std::size_t colon = at == std::string::npos ? std::string::npos : message.find(": ", at);
    if (colon != std::string::npos)
      message = message.substr(colon + 2);
    throw InputError(where, "invalid JSON: " + message);
  }
}

int check_format(const JsonObject& root, const std::string& expected_kind, int max_version) {
  const std::string expected = "\"" + expected_kind + "/" + std::to_string(max_version) + "\"";
  if (!root.has("format")) {
    root.fail("format", "missing required field (expected " + expected + ")");
  }
  const nlohmann::json& value = root.json().at("format");
  const std::string prefix = expected_kind + "/";
  if (!value.is_string() || value.get<std::string>().rfind(prefix, 0) != 0) {
    root.fail("format",
        "expected " + expected + ", got " + describe_json(value) + " (not an " + expected_kind
            + " file)");
  }
  const std::string version = value.get<std::string>().substr(prefix.size());
  const bool digits = !version.empty() && version.size() < 9
      && std::all_of(version.begin(), version.end(), [](char c) { return c >= '0' && c <= '9'; });
  const int v = digits ? std::stoi(version) : 0;
  if (v < 1)
    root.fail("format", "invalid version in " + describe_json(value));
  if (v > max_version) {
    root.fail("format",
        "version " + std::to_string(v) + " is newer than this elastolearn reads (up to " + expected
            + ")");
  }
  return v;
}

void write_json_file(const std::filesystem::path& path, const Json& value) {
  write_text_file_atomic(path, value.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
}

} // namespace elastolearn::io
