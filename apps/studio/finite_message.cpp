#include "studio/finite_message.hpp"

#include <cmath>
#include <fmt/format.h>

namespace cleave::studio {
namespace {

/// Depth-first search; `path` holds the pointer of `value`.
bool find_non_finite(const nlohmann::json& value, std::string& path) {
  if (value.is_number_float()) return !std::isfinite(value.get<double>());
  if (value.is_array()) {
    const std::size_t length = path.size();
    for (std::size_t i = 0; i < value.size(); ++i) {
      path += '/';
      path += std::to_string(i);
      if (find_non_finite(value[i], path)) return true;
      path.resize(length);
    }
  } else if (value.is_object()) {
    const std::size_t length = path.size();
    for (const auto& [key, item] : value.items()) {
      path += '/';
      path += key;
      if (find_non_finite(item, path)) return true;
      path.resize(length);
    }
  }
  return false;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

std::optional<std::string> first_non_finite(const nlohmann::json& message) {
  std::string path;
  if (find_non_finite(message, path)) return path;
  return std::nullopt;
}

std::string stage_of(std::string_view type, std::string_view pointer) {
  if (type == "frame") return "wound opening (frame)";
  if (type == "progress") return "progress";
  static const std::pair<std::string_view, std::string_view> kStages[] = {
      {"/fields/direction", "directions"},
      {"/fields/langer_kPa", "eigenvalues"},
      {"/fields/cross_kPa", "eigenvalues"},
      {"/fields/residual_kPa", "equilibration"},
      {"/equilibrium_residual", "equilibration"},
      {"/fields/displacement_mm", "incisions open (statics)"},
      {"/fields/cut_depth", "cut faces"},
      {"/fields/traction_kPa", "cut faces"},
      {"/surface", "surface"},
      {"/streamlines_mm", "streamlines"},
      {"/incisions", "incision measurement"},
      {"/wounds", "wound measurement"},
      {"/flaps", "wound measurement"},
      {"/timings_ms", "timings"},
  };
  for (const auto& [prefix, stage] : kStages)
    if (starts_with(pointer, prefix)) return std::string(stage);
  return type.empty() ? std::string("result") : std::string(type);
}

nlohmann::json checked_outgoing(nlohmann::json message) {
  const std::optional<std::string> bad = first_non_finite(message);
  if (!bad) return message;
  const std::string type = message.is_object() ? message.value("type", std::string()) : std::string();
  const std::string stage = stage_of(type, *bad);
  const double value = message.at(nlohmann::json::json_pointer(*bad)).get<double>();
  nlohmann::json error = {{"type", "error"},
                          {"stage", stage},
                          {"message", fmt::format("computation failed in stage '{}': {} is not finite ({}); the previous "
                                                  "result stays shown",
                                                  stage, *bad, value)}};
  for (const char* key : {"generation", "seq"})
    if (message.is_object() && message.contains(key)) error[key] = message[key];
  return error;
}

}  // namespace cleave::studio
