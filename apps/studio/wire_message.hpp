#pragma once
// How the studio's messages travel over the WebSocket. A message without packed arrays
// (packed_array.hpp) is JSON text. A message with them (results, frames) is one binary
// WebSocket message: its JSON without the arrays' bytes, then the bytes themselves,
//
//   offset 0   "CLV1"                          magic (never the start of JSON text)
//   offset 4   uint32 n                        length of the header
//   offset 8   n bytes of JSON                 the message; each packed array there is
//                                              {"packed": "f32", "count": c, "offset": o}
//   offset s   the arrays' bytes, little-endian float32 or uint32: s = 8 + n rounded up to a
//              multiple of 4 (zero padding), each array at s + o (o a multiple of 4).
//
// The page reads each array as a typed-array view on the received buffer (web/js/packed.js):
// nothing is formatted, escaped, base64-coded or parsed per number. Before this, a 45k-cell
// result was 3.4 MB of base64 inside JSON text (see docs/studio.md "Messages").
//
//   std::string bytes = wire_encoded(message);      // send as binary if is_binary_wire(bytes)
//   nlohmann::json back = wire_decoded(bytes);      // tests: packed arrays with their bytes
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace cleave::studio {

inline constexpr std::string_view kBinaryWireMagic = "CLV1";

/// JSON text when `message` holds no packed bytes, else the binary form above.
std::string wire_encoded(const nlohmann::json& message);
/// Whether `bytes` is the binary form (starts with the magic).
bool is_binary_wire(std::string_view bytes);
/// The message back from either form; packed arrays come back with their bytes
/// (unpacked_floats reads them). Throws InputError naming what does not fit: a short header, a
/// header that is not JSON, an array outside the message or not aligned.
nlohmann::json wire_decoded(std::string_view bytes);

}  // namespace cleave::studio
