#include "studio/wire_message.hpp"

#include <cstdint>
#include <cstring>
#include <fmt/format.h>
#include <vector>

#include "cleave/core/error.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

constexpr std::size_t kAlignment = 4;   ///< every array starts at a multiple of this
constexpr std::size_t kPrefixBytes = 8;  ///< magic and header length

std::size_t aligned(std::size_t bytes) { return (bytes + kAlignment - 1) / kAlignment * kAlignment; }

bool holds_bytes(const json& value) {
  return value.is_object() && value.contains("packed") && value.contains("bytes") && value["bytes"].is_binary();
}

/// `value` with each packed array's bytes replaced by its offset in the arrays' section; the
/// bytes are listed in `arrays` in that order.
json header_of(const json& value, std::vector<const json::binary_t*>& arrays, std::size_t& section_bytes) {
  if (holds_bytes(value)) {
    json h = json::object();
    for (const auto& [key, item] : value.items())
      if (key != "bytes") h[key] = item;
    h["offset"] = section_bytes;
    const json::binary_t& bytes = value["bytes"].get_binary();
    arrays.push_back(&bytes);
    section_bytes += aligned(bytes.size());
    return h;
  }
  if (value.is_object()) {
    json out = json::object();
    for (const auto& [key, item] : value.items()) out[key] = header_of(item, arrays, section_bytes);
    return out;
  }
  if (value.is_array()) {
    json out = json::array();
    for (const json& item : value) out.push_back(header_of(item, arrays, section_bytes));
    return out;
  }
  return value;
}

std::size_t element_bytes(const std::string& kind) {
  if (kind == "f32" || kind == "u32") return 4;
  throw InputError(fmt::format("binary message: packed array of unknown kind '{}'; expected f32 or u32", kind));
}

/// Puts each array's bytes back from the arrays' section (`section`, `section_bytes` long).
void restore_arrays(json& value, const char* section, std::size_t section_bytes) {
  if (value.is_object() && value.contains("packed") && value.contains("offset")) {
    if (!value["packed"].is_string() || !value["count"].is_number_unsigned() || !value["offset"].is_number_unsigned())
      throw InputError(fmt::format("binary message: packed array {} needs a kind, a count and an offset", value.dump()));
    const auto offset = value["offset"].get<std::size_t>();
    const auto count = value["count"].get<std::size_t>();
    const std::size_t bytes = count * element_bytes(value["packed"].get<std::string>());
    if (offset % kAlignment != 0 || offset > section_bytes || bytes > section_bytes - offset)
      throw InputError(fmt::format("binary message: array of {} bytes at offset {} does not fit the {} bytes of arrays (or is "
                                   "not aligned to {})",
                                   bytes, offset, section_bytes, kAlignment));
    json::binary_t data(std::vector<std::uint8_t>(section + offset, section + offset + bytes));
    value.erase("offset");
    value["bytes"] = json::binary(std::move(data));
    return;
  }
  if (value.is_structured())
    for (json& item : value) restore_arrays(item, section, section_bytes);
}

}  // namespace

bool is_binary_wire(std::string_view bytes) { return bytes.substr(0, kBinaryWireMagic.size()) == kBinaryWireMagic; }

std::string wire_encoded(const json& message) {
  std::vector<const json::binary_t*> arrays;
  std::size_t section_bytes = 0;
  const json header = header_of(message, arrays, section_bytes);
  if (arrays.empty()) return message.dump();
  const std::string header_text = header.dump();
  const auto header_bytes = static_cast<std::uint32_t>(header_text.size());
  const std::size_t section_start = aligned(kPrefixBytes + header_text.size());
  std::string out(section_start + section_bytes, '\0');
  std::memcpy(out.data(), kBinaryWireMagic.data(), kBinaryWireMagic.size());
  std::memcpy(out.data() + kBinaryWireMagic.size(), &header_bytes, sizeof header_bytes);  // little-endian hosts (packed_array.cpp)
  std::memcpy(out.data() + kPrefixBytes, header_text.data(), header_text.size());
  std::size_t at = section_start;
  for (const json::binary_t* bytes : arrays) {
    if (!bytes->empty()) std::memcpy(out.data() + at, bytes->data(), bytes->size());
    at += aligned(bytes->size());
  }
  return out;
}

json wire_decoded(std::string_view bytes) {
  if (!is_binary_wire(bytes)) {
    json text = json::parse(bytes, nullptr, false);
    if (text.is_discarded()) throw InputError("wire message: neither JSON text nor a binary message (which starts with CLV1)");
    return text;
  }
  if (bytes.size() < kPrefixBytes)
    throw InputError(fmt::format("binary message: {} bytes; expected at least {} (magic and header length)", bytes.size(), kPrefixBytes));
  std::uint32_t header_bytes = 0;
  std::memcpy(&header_bytes, bytes.data() + kBinaryWireMagic.size(), sizeof header_bytes);
  if (header_bytes > bytes.size() - kPrefixBytes)
    throw InputError(fmt::format("binary message: a header of {} bytes runs past the message's {} bytes", header_bytes, bytes.size()));
  json message = json::parse(bytes.substr(kPrefixBytes, header_bytes), nullptr, false);
  if (message.is_discarded()) throw InputError("binary message: the header is not JSON");
  const std::size_t section_start = aligned(kPrefixBytes + header_bytes);
  const std::size_t section_bytes = bytes.size() > section_start ? bytes.size() - section_start : 0;
  restore_arrays(message, bytes.data() + std::min(section_start, bytes.size()), section_bytes);
  return message;
}

}  // namespace cleave::studio
