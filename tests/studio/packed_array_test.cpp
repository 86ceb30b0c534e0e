// Packed arrays of the studio's messages (apps/studio/packed_array.hpp): float and index arrays
// that come back bit for bit through the wire (wire_message.hpp), and a float array with a NaN
// that stays a JSON array so that the finiteness check still names the stage.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"
#include "studio/finite_message.hpp"
#include "studio/packed_array.hpp"
#include "studio/wire_message.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

TEST(PackedArray, FloatsAndIndicesComeBackBitForBit) {
  const std::vector<float> values = {0.0f, -0.0f, 1.5f, -123.456f, std::numeric_limits<float>::min(),
                                     std::numeric_limits<float>::max(), 3.14159265f};
  const json p = packed_floats(values);
  EXPECT_EQ(p["packed"], "f32");
  EXPECT_EQ(p["count"], values.size());
  EXPECT_EQ(p["bytes"].get_binary().size(), 4 * values.size());
  const std::vector<float> back = unpacked_floats(wire_decoded(wire_encoded(json{{"a", p}}))["a"]);
  ASSERT_EQ(back.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(std::signbit(back[i]), std::signbit(values[i]));
  EXPECT_EQ(back, values);

  const std::vector<std::uint32_t> indices = {0, 1, 2, 65535, 65536, 4294967295u};
  const json q = packed_indices(indices);
  EXPECT_EQ(q["packed"], "u32");
  EXPECT_EQ(unpacked_indices(wire_decoded(wire_encoded(json{{"q", q}}))["q"]), indices);
  EXPECT_EQ(unpacked_floats(packed_floats(std::vector<float>{})), std::vector<float>{});
  EXPECT_EQ(unpacked_floats(json::array({1.0, 2.5})), (std::vector<float>{1.0f, 2.5f})) << "a plain array reads too";
}

TEST(PackedArray, ANonFiniteFloatStaysAPlainArrayAndIsNamedByItsStage) {
  const std::vector<float> values = {1.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f};
  const json field = packed_floats(values);
  ASSERT_TRUE(field.is_array());
  const json out = checked_outgoing({{"type", "result"}, {"fields", {{"langer_kPa", field}}}});
  EXPECT_EQ(out["type"], "error");
  EXPECT_EQ(out["stage"], "eigenvalues");
  EXPECT_NE(out["message"].get<std::string>().find("/fields/langer_kPa/1"), std::string::npos) << out.dump();
}

TEST(PackedArray, MismatchedPackingIsRejected) {
  const json p = packed_floats(std::vector<float>{1.0f, 2.0f});
  json wrong_count = p;
  wrong_count["count"] = 3;
  try {
    unpacked_floats(wrong_count);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "packed array: 8 bytes for 3 values of 4 bytes");
  }
  EXPECT_THROW(unpacked_indices(p), InputError) << "f32 is not u32";
  EXPECT_THROW(unpacked_floats(json("text")), InputError);
}

}  // namespace
}  // namespace cleave::studio
