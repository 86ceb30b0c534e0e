#pragma once
// Reading validated values out of a JSON document. Every error names the file, the JSON path
// (e.g. "/materials/1/E_kPa"), the value found and what was expected.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// A position in a JSON document, for error messages.
struct JsonPath {
  std::string file;  ///< file name (or "message" for studio messages)
  std::string path;  ///< JSON pointer, "" for the root

  JsonPath operator/(const std::string& key) const { return {file, path + "/" + key}; }
  JsonPath operator/(std::size_t index) const { return {file, path + "/" + std::to_string(index)}; }
  std::string str() const { return file + ": " + (path.empty() ? "/" : path); }
};

/// Throws InputError "<file>: <path> is <value>; expected <expected>".
[[noreturn]] void json_error(const JsonPath& at, const nlohmann::json& value, const std::string& expected);
/// Throws InputError "<file>: <path> is missing; expected <expected>".
[[noreturn]] void json_missing(const JsonPath& at, const std::string& expected);

/// Rejects keys in `object` that are not in `allowed` (catches typos such as "E_kpa").
void json_allow_keys(const nlohmann::json& object, const JsonPath& at, std::initializer_list<const char*> allowed);

const nlohmann::json& json_object(const nlohmann::json& parent, const std::string& key, const JsonPath& at);
double json_number(const nlohmann::json& value, const JsonPath& at);
/// A finite number in [lo, hi] (inclusive unless the bound is +-infinity).
double json_number_in(const nlohmann::json& value, const JsonPath& at, double lo, double hi, const std::string& expected);
/// A stress in kPa: finite and at most units::kLargestStress_kPa in magnitude (case files).
double json_stress_kPa(const nlohmann::json& value, const JsonPath& at);
int json_int_in(const nlohmann::json& value, const JsonPath& at, int lo, int hi);
std::string json_string(const nlohmann::json& value, const JsonPath& at);
bool json_bool(const nlohmann::json& value, const JsonPath& at);
Vec3 json_vec3(const nlohmann::json& value, const JsonPath& at);
std::vector<Vec3> json_points(const nlohmann::json& value, const JsonPath& at);

/// Value of an optional key, or std::nullopt when absent.
inline const nlohmann::json* json_find(const nlohmann::json& object, const std::string& key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

/// Parses JSON text; syntax errors become InputError with file, line/byte and nlohmann's reason.
/// Refuses nesting deeper than 64 levels. The message is valid UTF-8 even when the text is not
/// (nlohmann quotes the offending bytes; they are replaced by U+FFFD), so that it can be sent
/// back as JSON.
nlohmann::json parse_json_text(const std::string& text, const std::string& file);

/// `text` with every byte that is not part of a well-formed UTF-8 sequence replaced by U+FFFD.
std::string utf8_sanitized(std::string_view text);

/// The longest prefix of valid UTF-8 `text` of at most `max_bytes` bytes that does not cut a
/// character in two (a cut character would make the message invalid UTF-8, which nlohmann's
/// dump refuses with an exception).
std::string utf8_prefix(std::string_view text, std::size_t max_bytes);

}  // namespace cleave
