#pragma once
// Large numeric arrays of the studio's messages (surface positions, triangles, per-vertex fields,
// frames) are packed: their little-endian float32 or uint32 bytes as a JSON binary value,
//
//   {"packed": "f32", "count": 141000, "bytes": <binary>}
//
// instead of a JSON array of numbers. A message holding them travels as one binary WebSocket
// message (wire_message.hpp): the JSON around them, then their bytes, which the page reads as
// typed arrays without parsing them (web/js/packed.js). At 45k cells a result holds 700,000
// numbers: as decimals in JSON text (until session 5) they took 0.17 s per edit to write, check
// and parse; as base64 in JSON text (sessions 5-16) 3.4 MB and 20-40 ms. A float array holding
// a NaN or Inf is not packed: it stays a JSON array so that checked_outgoing
// (finite_message.hpp) finds the value and names its stage.
//
//   message["surface"]["positions_mm"] = packed_floats(positions);
//   std::vector<float> back = unpacked_floats(message["surface"]["positions_mm"]);   // tests
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace cleave::studio {

/// {"packed":"f32","count":n,"bytes":...} of `values`; a plain array when any is not finite.
nlohmann::json packed_floats(std::span<const float> values);
/// {"packed":"u32","count":n,"bytes":...} of `values`.
nlohmann::json packed_indices(std::span<const std::uint32_t> values);

/// The values of a packed (or plain) float array; throws InputError for anything else.
std::vector<float> unpacked_floats(const nlohmann::json& array);
/// The values of a packed (or plain) index array; throws InputError for anything else.
std::vector<std::uint32_t> unpacked_indices(const nlohmann::json& array);

}  // namespace cleave::studio
