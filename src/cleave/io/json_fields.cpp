#include "cleave/io/json_fields.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

std::string describe(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

}  // namespace

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
    throw InputError(fmt::format("{}: invalid JSON at byte {}: {}", file, e.byte, reason));
  } catch (const nlohmann::json::exception& e) {
    // e.g. out_of_range.406 "number overflow parsing '1e999'"
    std::string reason = e.what();
    const auto bracket = reason.find("] ");
    if (bracket != std::string::npos) reason = reason.substr(bracket + 2);
    throw InputError(fmt::format("{}: invalid JSON: {}", file, reason));
  }
}

}  // namespace cleave
