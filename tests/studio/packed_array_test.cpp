// Packed arrays of the studio's messages (apps/studio/packed_array.hpp): RFC 4648 base64, float
// and index arrays that come back bit for bit, and a float array with a NaN that stays a JSON
// array so that the finiteness check still names the stage.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"
#include "studio/finite_message.hpp"
#include "studio/packed_array.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

std::vector<std::uint8_t> bytes_of(std::string_view s) { return {s.begin(), s.end()}; }

TEST(PackedArray, Base64IsTheRfc4648Alphabet) {
  // RFC 4648 section 10 test vectors.
  const std::pair<const char*, const char*> vectors[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},  {"foob", "Zm9vYg=="},  {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(base64_encoded(bytes_of(plain)), encoded) << plain;
    EXPECT_EQ(base64_decoded(encoded), bytes_of(plain)) << encoded;
  }
  const std::vector<std::uint8_t> high = {0xfb, 0xff, 0xbf, 0x00};
  EXPECT_EQ(base64_encoded(high), "+/+/AA==") << "the last two characters are + and /";
  EXPECT_EQ(base64_decoded("+/+/AA=="), high);
}

TEST(PackedArray, BadBase64IsNamed) {
  try {
    base64_decoded("Zm9*");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "base64: character '*' at 3 is not base64");
  }
  try {
    base64_decoded("Zm9");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "base64: 3 characters; expected a multiple of 4");
  }
  EXPECT_THROW(base64_decoded("Z=9v"), InputError) << "padding only at the end";
}

TEST(PackedArray, FloatsAndIndicesComeBackBitForBit) {
  const std::vector<float> values = {0.0f, -0.0f, 1.5f, -123.456f, std::numeric_limits<float>::min(),
                                     std::numeric_limits<float>::max(), 3.14159265f};
  const json p = packed_floats(values);
  EXPECT_EQ(p["packed"], "f32");
  EXPECT_EQ(p["count"], values.size());
  EXPECT_EQ(p["base64"].get<std::string>().size(), 4 * ((4 * values.size() + 2) / 3));
  const std::vector<float> back = unpacked_floats(json::parse(p.dump()));
  ASSERT_EQ(back.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(std::signbit(back[i]), std::signbit(values[i]));
  EXPECT_EQ(back, values);

  const std::vector<std::uint32_t> indices = {0, 1, 2, 65535, 65536, 4294967295u};
  const json q = packed_indices(indices);
  EXPECT_EQ(q["packed"], "u32");
  EXPECT_EQ(unpacked_indices(json::parse(q.dump())), indices);
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
