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

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// 0..63 for a base64 character, -1 otherwise.
int sextet_of(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

template <typename T>
nlohmann::json packed(std::span<const T> values, const char* kind) {
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(values.data()), values.size_bytes());
  return {{"packed", kind}, {"count", values.size()}, {"base64", base64_encoded(bytes)}};
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
  if (!array.is_object() || array.value("packed", "") != kind || !array.contains("count") || !array.contains("base64"))
    throw InputError(fmt::format("packed array: expected {{\"packed\": \"{}\", \"count\": n, \"base64\": ...}} or an array", kind));
  const std::vector<std::uint8_t> bytes = base64_decoded(array["base64"].get<std::string>());
  const auto count = array["count"].get<std::size_t>();
  if (bytes.size() != count * sizeof(T))
    throw InputError(fmt::format("packed array: {} bytes for {} values of {} bytes", bytes.size(), count, sizeof(T)));
  out.resize(count);
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());  // an empty vector's data() may be null
  return out;
}

}  // namespace

std::string base64_encoded(std::span<const std::uint8_t> bytes) {
  std::string out;
  out.reserve(4 * ((bytes.size() + 2) / 3));
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (const std::size_t left = bytes.size() - i; left > 0) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (left == 2 ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += left == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::vector<std::uint8_t> base64_decoded(std::string_view text) {
  if (text.size() % 4 != 0) throw InputError(fmt::format("base64: {} characters; expected a multiple of 4", text.size()));
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    const int padding = !last || text[i + 3] != '=' ? 0 : text[i + 2] == '=' ? 2 : 1;
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + static_cast<std::size_t>(k)];
      const int s = k >= 4 - padding ? 0 : sextet_of(c);
      if (s < 0) throw InputError(fmt::format("base64: character '{}' at {} is not base64", c, i + static_cast<std::size_t>(k)));
      v = (v << 6) | static_cast<std::uint32_t>(s);
    }
    out.push_back(static_cast<std::uint8_t>(v >> 16));
    if (padding < 2) out.push_back(static_cast<std::uint8_t>(v >> 8));
    if (padding < 1) out.push_back(static_cast<std::uint8_t>(v));
  }
  return out;
}

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
