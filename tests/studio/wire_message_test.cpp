// The studio's wire format (apps/studio/wire_message.hpp): messages without packed arrays stay
// JSON text; messages with them become one binary message whose header is the JSON and whose
// arrays follow at aligned offsets; the decoder gives back the same message and names what does
// not fit in a damaged one.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "cleave/core/error.hpp"
#include "studio/packed_array.hpp"
#include "studio/wire_message.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

std::uint32_t header_length(const std::string& bytes) {
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 4, sizeof n);
  return n;
}

std::string message_of_throw(const std::string& bytes) {
  try {
    wire_decoded(bytes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// A result-like message: arrays of 3, 1 and 0 values (3 and 1 leave padding), nested in objects
/// and in an array, beside plain values.
json sample() {
  return {{"type", "result"},
          {"seq", 7},
          {"surface", {{"id", "s1"}, {"positions_mm", packed_floats(std::vector<float>{1.5f, -2.0f, 3.25f})}}},
          {"fields", {{"langer_kPa", packed_floats(std::vector<float>{0.125f})}, {"empty", packed_floats(std::vector<float>{})}}},
          {"streamlines_mm", json::array({packed_floats(std::vector<float>{4.0f, 5.0f}), packed_indices(std::vector<std::uint32_t>{9})})},
          {"timings_ms", {{"total", 12.5}}}};
}

TEST(WireMessage, AMessageWithoutPackedArraysIsJsonText) {
  const json state = {{"type", "state"}, {"seq", 3}, {"values", {1, 2, 3}}};
  const std::string bytes = wire_encoded(state);
  EXPECT_EQ(bytes, state.dump());
  EXPECT_FALSE(is_binary_wire(bytes));
  EXPECT_EQ(wire_decoded(bytes), state);
}

TEST(WireMessage, PackedArraysTravelAsBytesAfterTheHeaderAtAlignedOffsets) {
  const json message = sample();
  const std::string bytes = wire_encoded(message);
  ASSERT_TRUE(is_binary_wire(bytes));
  ASSERT_EQ(bytes.substr(0, 4), "CLV1");
  const std::uint32_t n = header_length(bytes);
  const json header = json::parse(bytes.substr(8, n));
  EXPECT_EQ(header["seq"], 7);
  EXPECT_EQ(header["timings_ms"]["total"], 12.5);
  EXPECT_FALSE(header["surface"]["positions_mm"].contains("bytes")) << "no bytes inside the JSON";
  EXPECT_EQ(header["surface"]["positions_mm"]["count"], 3);

  // The arrays follow the header, aligned, in the header's key order; each is where its offset says.
  const std::size_t start = (8 + n + 3) / 4 * 4;
  for (std::size_t i = 8 + n; i < start; ++i) EXPECT_EQ(bytes[i], '\0') << "zero padding";
  const auto float_at = [&](const json& packed, std::size_t k) {
    float v = 0;
    std::memcpy(&v, bytes.data() + start + packed["offset"].get<std::size_t>() + 4 * k, sizeof v);
    return v;
  };
  EXPECT_EQ(float_at(header["surface"]["positions_mm"], 2), 3.25f);
  EXPECT_EQ(float_at(header["fields"]["langer_kPa"], 0), 0.125f);
  EXPECT_EQ(float_at(header["streamlines_mm"][0], 1), 5.0f);
  for (const json* p : {&header["surface"]["positions_mm"], &header["fields"]["langer_kPa"], &header["streamlines_mm"][1]})
    EXPECT_EQ((*p)["offset"].get<std::size_t>() % 4, 0u);
  EXPECT_EQ(bytes.size(), start + 4 * (3 + 1 + 0 + 2 + 1)) << "four-byte values need no padding between arrays";

  EXPECT_EQ(wire_decoded(bytes), message) << "the same message back, bytes and all";
}

TEST(WireMessage, ADamagedBinaryMessageIsNamed) {
  const std::string good = wire_encoded(sample());
  EXPECT_EQ(message_of_throw("CLV1ab"), "binary message: 6 bytes; expected at least 8 (magic and header length)");
  std::string long_header = good;
  const std::uint32_t too_long = 1u << 30;
  std::memcpy(long_header.data() + 4, &too_long, sizeof too_long);
  EXPECT_EQ(message_of_throw(long_header),
            "binary message: a header of 1073741824 bytes runs past the message's " + std::to_string(good.size()) + " bytes");
  const std::string cut_short = good.substr(0, good.size() - 4);
  EXPECT_NE(message_of_throw(cut_short).find("does not fit the"), std::string::npos) << message_of_throw(cut_short);
  std::string not_json = good;
  not_json[8] = '!';
  EXPECT_EQ(message_of_throw(not_json), "binary message: the header is not JSON");
  EXPECT_EQ(message_of_throw("{\"type\""), "wire message: neither JSON text nor a binary message (which starts with CLV1)");

  // A header whose array is misaligned or of an unknown kind.
  const auto with_header = [](const json& header, std::size_t arrays_bytes) {
    const std::string text = header.dump();
    const auto n = static_cast<std::uint32_t>(text.size());
    std::string out = "CLV1";
    out.append(reinterpret_cast<const char*>(&n), sizeof n);
    out += text;
    out.resize((out.size() + 3) / 4 * 4 + arrays_bytes, '\0');
    return out;
  };
  EXPECT_EQ(message_of_throw(with_header({{"a", {{"packed", "f32"}, {"count", 1}, {"offset", 2}}}}, 8)),
            "binary message: array of 4 bytes at offset 2 does not fit the 8 bytes of arrays (or is not aligned to 4)");
  EXPECT_EQ(message_of_throw(with_header({{"a", {{"packed", "f64"}, {"count", 1}, {"offset", 0}}}}, 8)),
            "binary message: packed array of unknown kind 'f64'; expected f32 or u32");
  EXPECT_EQ(wire_decoded(with_header({{"a", {{"packed", "u32"}, {"count", 2}, {"offset", 0}}}}, 8))["a"]["bytes"].get_binary().size(), 8u);
}

}  // namespace
}  // namespace cleave::studio
