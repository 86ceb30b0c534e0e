#include "cleave/io/json_fields.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/core/units.hpp"

namespace cleave {
namespace {

constexpr std::size_t kMaxDescribedBytes = 60;  // a value quoted in an error message

std::string describe(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
  if (text.size() > kMaxDescribedBytes) text = utf8_prefix(text, kMaxDescribedBytes - 3) + "...";
  return text;
}

/// Length of the well-formed UTF-8 sequence starting at text[i], or 0 when it is not one.
std::size_t utf8_sequence_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b = byte(i);
  std::size_t n = 0;
  unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte (no overlongs, no surrogates)
  if (b < 0x80) return 1;
  if (b >= 0xC2 && b <= 0xDF) n = 2;
  else if (b >= 0xE0 && b <= 0xEF) { n = 3; if (b == 0xE0) lo = 0xA0; if (b == 0xED) hi = 0x9F; }
  else if (b >= 0xF0 && b <= 0xF4) { n = 4; if (b == 0xF0) lo = 0x90; if (b == 0xF4) hi = 0x8F; }
  else return 0;
  if (i + n > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}

}  // namespace

std::string utf8_sanitized(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence_length(text, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string utf8_prefix(std::string_view text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return std::string(text);
  std::size_t end = max_bytes;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;  // continuation byte
  return std::string(text.substr(0, end));
}

void json_error(const JsonPath& at, const nlohmann::json& value, const std::string& expected) {
  throw InputError(fmt::format("{} is {}; expected {}", at.str(), describe(value), expected));
}

void json_missing(const JsonPath& at, const std::string& expected) {
  throw InputError(fmt::format("{} is missing; expected {}", at.str(), expected));
}

void json_allow_keys(const nlohmann::json& object, const JsonPath& at, std::initializer_list<const char*> allowed) {
  if (!object.is_object()) json_error(at, object, "an object");
  for (const auto& [key, value] : object.items()) {
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (known) continue;
    std::string list;
    for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    throw InputError(fmt::format("{} has unknown key '{}'; expected one of: {}", at.str(), key, list));
  }
}

const nlohmann::json& json_object(const nlohmann::json& parent, const std::string& key, const JsonPath& at) {
  const nlohmann::json* value = json_find(parent, key);
  if (!value) json_missing(at / key, "an object");
  if (!value->is_object()) json_error(at / key, *value, "an object");
  return *value;
}

double json_number(const nlohmann::json& value, const JsonPath& at) {
  if (!value.is_number()) json_error(at, value, "a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) json_error(at, value, "a finite number");
  return x;
}

double json_number_in(const nlohmann::json& value, const JsonPath& at, double lo, double hi, const std::string& expected) {
  if (!value.is_number()) json_error(at, value, expected);
  const double x = value.get<double>();
  if (!std::isfinite(x) || x < lo || x > hi) json_error(at, value, expected);
  return x;
}

double json_stress_kPa(const nlohmann::json& value, const JsonPath& at) {
  static_assert(units::kLargestStress_kPa == 1e9, "the message below names the bound");
  return json_number_in(value, at, -units::kLargestStress_kPa, units::kLargestStress_kPa,
                        "a finite stress in kPa, at most 1e9 in magnitude");
}

int json_int_in(const nlohmann::json& value, const JsonPath& at, int lo, int hi) {
  const std::string expected = fmt::format("an integer from {} to {}", lo, hi);
  if (!value.is_number_integer()) json_error(at, value, expected);
  const auto x = value.get<long long>();
  if (x < lo || x > hi) json_error(at, value, expected);
  return static_cast<int>(x);
}

std::string json_string(const nlohmann::json& value, const JsonPath& at) {
  if (!value.is_string()) json_error(at, value, "a string");
  return value.get<std::string>();
}

bool json_bool(const nlohmann::json& value, const JsonPath& at) {
  if (!value.is_boolean()) json_error(at, value, "true or false");
  return value.get<bool>();
}

Vec3 json_vec3(const nlohmann::json& value, const JsonPath& at) {
  if (!value.is_array() || value.size() != 3) json_error(at, value, "[x, y, z] (three numbers)");
  return {json_number(value[0], at / 0), json_number(value[1], at / 1), json_number(value[2], at / 2)};
}

std::vector<Vec3> json_points(const nlohmann::json& value, const JsonPath& at) {
  if (!value.is_array()) json_error(at, value, "an array of [x, y, z] points (mm)");
  std::vector<Vec3> points;
  points.reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) points.push_back(json_vec3(value[i], at / i));
  return points;
}

nlohmann::json parse_json_text(const std::string& text, const std::string& file) {
  constexpr int kMaxDepth = 64;
  int depth = 0;
  bool too_deep = false;
  const auto limit_depth = [&](int d, nlohmann::json::parse_event_t event, nlohmann::json&) {
    if (event == nlohmann::json::parse_event_t::object_start || event == nlohmann::json::parse_event_t::array_start) {
      depth = d;
      if (d > kMaxDepth) too_deep = true;
    }
    return !too_deep;
  };
  try {
    nlohmann::json doc = nlohmann::json::parse(text, limit_depth);
    if (too_deep) throw InputError(fmt::format("{}: JSON nested deeper than {} levels", file, kMaxDepth));
    return doc;
  } catch (const nlohmann::json::parse_error& e) {
    if (too_deep) throw InputError(fmt::format("{}: JSON nested deeper than {} levels", file, kMaxDepth));
    std::string reason = e.what();
    const auto colon = reason.find("syntax error");
    if (colon != std::string::npos) reason = reason.substr(colon);
    throw InputError(fmt::format("{}: invalid JSON at byte {}: {}", file, e.byte, utf8_sanitized(reason)));
  } catch (const nlohmann::json::exception& e) {
    // e.g. out_of_range.406 "number overflow parsing '1e999'"
    std::string reason = e.what();
    const auto bracket = reason.find("] ");
    if (bracket != std::string::npos) reason = reason.substr(bracket + 2);
    throw InputError(fmt::format("{}: invalid JSON: {}", file, utf8_sanitized(reason)));
  }
}

}  // namespace cleave
