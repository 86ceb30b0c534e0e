#pragma once
// Large numeric arrays of the studio's messages (surface positions, triangles, per-vertex fields,
// frames) travel packed: the bytes of little-endian float32 or uint32 values in base64,
//
//   {"packed": "f32", "count": 141000, "base64": "AACAPwAAAEA..."}
//
// instead of a JSON array of numbers. At 45k cells a result held 700,000 numbers (5.6 MB of
// text): writing them as decimals, checking them and parsing them in the page took 0.17 s per
// edit; a packed array is copied, not formatted. The page unpacks them into typed arrays
// (web/js/packed.js). A float array holding a NaN or Inf is not packed: it stays a JSON array so
// that checked_outgoing (finite_message.hpp) finds the value and names its stage.
//
//   message["surface"]["positions_mm"] = packed_floats(positions);
//   std::vector<float> back = unpacked_floats(message["surface"]["positions_mm"]);   // tests
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace cleave::studio {

/// RFC 4648 base64 (with '=' padding).
std::string base64_encoded(std::span<const std::uint8_t> bytes);
/// The inverse; throws InputError naming the offending character for text that is not base64.
std::vector<std::uint8_t> base64_decoded(std::string_view text);

/// {"packed":"f32","count":n,"base64":...} of `values`; a plain array when any is not finite.
nlohmann::json packed_floats(std::span<const float> values);
/// {"packed":"u32","count":n,"base64":...} of `values`.
nlohmann::json packed_indices(std::span<const std::uint32_t> values);

/// The values of a packed (or plain) float array; throws InputError for anything else.
std::vector<float> unpacked_floats(const nlohmann::json& array);
/// The values of a packed (or plain) index array; throws InputError for anything else.
std::vector<std::uint32_t> unpacked_indices(const nlohmann::json& array);

}  // namespace cleave::studio
