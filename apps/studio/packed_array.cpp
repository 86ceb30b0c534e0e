#include "studio/packed_array.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave::studio {
namespace {

static_assert(std::endian::native == std::endian::little, "packed arrays carry the host's bytes: little-endian hosts only");

template <typename T>
nlohmann::json packed(std::span<const T> values, const char* kind) {
  const auto* first = reinterpret_cast<const std::uint8_t*>(values.data());
  return {{"packed", kind}, {"count", values.size()}, {"bytes", nlohmann::json::binary({first, first + values.size_bytes()})}};
}

template <typename T>
std::vector<T> unpacked(const nlohmann::json& array, const char* kind) {
  std::vector<T> out;
  if (array.is_array()) {
    out.reserve(array.size());
    for (const nlohmann::json& v : array) {
      if (!v.is_number()) throw InputError(fmt::format("packed array: element {} is not a number", v.dump()));
      out.push_back(v.get<T>());
    }
    return out;
  }
  if (!array.is_object() || array.value("packed", "") != kind || !array.contains("count") || !array.contains("bytes") ||
      !array["bytes"].is_binary())
    throw InputError(fmt::format("packed array: expected {{\"packed\": \"{}\", \"count\": n, \"bytes\": binary}} or an array", kind));
  const nlohmann::json::binary_t& bytes = array["bytes"].get_binary();
  const auto count = array["count"].get<std::size_t>();
  if (bytes.size() != count * sizeof(T))
    throw InputError(fmt::format("packed array: {} bytes for {} values of {} bytes", bytes.size(), count, sizeof(T)));
  out.resize(count);
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());  // an empty vector's data() may be null
  return out;
}

}  // namespace

nlohmann::json packed_floats(std::span<const float> values) {
  if (std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); })) return packed(values, "f32");
  nlohmann::json plain = nlohmann::json::array();
  for (float v : values) plain.push_back(static_cast<double>(v));
  return plain;
}

nlohmann::json packed_indices(std::span<const std::uint32_t> values) { return packed(values, "u32"); }

std::vector<float> unpacked_floats(const nlohmann::json& array) { return unpacked<float>(array, "f32"); }

std::vector<std::uint32_t> unpacked_indices(const nlohmann::json& array) { return unpacked<std::uint32_t>(array, "u32"); }

}  // namespace cleave::studio
