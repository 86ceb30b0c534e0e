// Numerical safety of what the studio sends (issue 8): a non-finite number anywhere in an
// outgoing message becomes an error that names the stage; finite messages pass unchanged.
#include <gtest/gtest.h>

#include <limits>

#include "studio/finite_message.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

json small_result() {
  return {{"type", "result"},
          {"generation", 4},
          {"seq", 3},
          {"surface", {{"positions_mm", {0.0, 1.0, 2.0, 3.0, 4.0, 5.0}}, {"triangles", {0, 1, 0}}}},
          {"fields", {{"direction", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0}}, {"langer_kPa", {20.0, 19.5}}, {"cross_kPa", {10.0, 9.0}}}},
          {"incisions", {{{"centre_mm", {1.0, 2.0, 3.0}}, {"opening_mm", 1.2}, {"gap_mm", 0.4}}}},
          {"timings_ms", {{"eigenvalues", 12.5}, {"total", 40.0}}}};
}

TEST(FiniteMessage, AFiniteMessagePassesUnchanged) {
  const json m = small_result();
  EXPECT_EQ(first_non_finite(m), std::nullopt);
  EXPECT_EQ(checked_outgoing(m), m);
}

TEST(FiniteMessage, ANaNEigenvalueBecomesAnErrorNamingTheStage) {
  json m = small_result();
  m["fields"]["langer_kPa"][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite(m), "/fields/langer_kPa/1");
  const json out = checked_outgoing(m);
  EXPECT_EQ(out["type"], "error");
  EXPECT_EQ(out["stage"], "eigenvalues");
  EXPECT_EQ(out["generation"], 4);
  EXPECT_EQ(out["seq"], 3);
  EXPECT_EQ(out["message"],
            "computation failed in stage 'eigenvalues': /fields/langer_kPa/1 is not finite (nan); the previous result "
            "stays shown");
  EXPECT_EQ(out.dump().find("null"), std::string::npos) << "nothing non-finite (written as null) goes out";
}

TEST(FiniteMessage, EveryStageOfAResultIsNamed) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::pair<json::json_pointer, std::string> cases[] = {
      {json::json_pointer("/surface/positions_mm/4"), "surface"},
      {json::json_pointer("/fields/direction/0"), "directions"},
      {json::json_pointer("/fields/cross_kPa/0"), "eigenvalues"},
      {json::json_pointer("/incisions/0/opening_mm"), "incision measurement"},
      {json::json_pointer("/incisions/0/centre_mm/2"), "incision measurement"},
      {json::json_pointer("/timings_ms/total"), "timings"},
  };
  for (const auto& [where, stage] : cases) {
    json m = small_result();
    m[where] = -inf;
    const json out = checked_outgoing(m);
    EXPECT_EQ(out["type"], "error") << where;
    EXPECT_EQ(out["stage"], stage) << where;
  }
  json m = small_result();
  m["fields"]["displacement_mm"] = {0.5, inf};
  EXPECT_EQ(checked_outgoing(m)["stage"], "incisions open (statics)");
  m = small_result();
  m["wounds"] = {{{"cut", 7}, {"width_mm", std::nan("")}}};
  EXPECT_EQ(checked_outgoing(m)["stage"], "wound measurement");
  m = small_result();
  m["streamlines_mm"] = {{0.0, 1.0, inf}};
  EXPECT_EQ(checked_outgoing(m)["stage"], "streamlines");
}

TEST(FiniteMessage, ANonFiniteFrameNamesTheWoundOpening) {
  const json frame = {{"type", "frame"}, {"generation", 9}, {"index", 2}, {"positions_mm", {0.0, std::nan(""), 1.0}},
                      {"width_mm", 0.3}};
  const json out = checked_outgoing(frame);
  EXPECT_EQ(out["type"], "error");
  EXPECT_EQ(out["stage"], "wound opening (frame)");
  EXPECT_EQ(out["generation"], 9);
  EXPECT_NE(out["message"].get<std::string>().find("/positions_mm/1"), std::string::npos);
}

}  // namespace
}  // namespace cleave::studio
