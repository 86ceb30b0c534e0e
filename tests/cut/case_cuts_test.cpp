// The case sections "incisions" and "cuts": what they parse into and their exact refusals.
#include <gtest/gtest.h>

#include "cleave/core/error.hpp"
#include "cleave/io/case_cuts.hpp"

namespace cleave {
namespace {

CaseFile case_with(const std::string& sections) {
  return parse_case_text(R"({"model": {"source": "plate"})" + sections + "}", "case.json", ".");
}

std::string refusal(const std::string& sections) {
  try {
    parse_case_cuts(case_with(sections));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CaseCuts, ParsesIncisionsAndCuts) {
  const CaseCuts c = parse_case_cuts(case_with(R"(,
    "incisions": {"radius_mm": 5, "depth_mm": 4, "plug": "keep", "at_mm": [[50, 50, 10]],
                  "place": {"spacing_mm": 20, "count": 3, "region": {"sphere_mm": {"centre": [50, 50, 10], "radius": 30}}, "seed": 9}},
    "cuts": [{"type": "flap", "path_mm": [[1, 1, 10], [1, 9, 10], [9, 9, 10]], "depth_mm": 3, "shape": "closed"},
             {"type": "scalpel", "path_mm": [[0, 0, 10], [10, 0, 10]], "depth_mm": 2, "blade_angle_deg": 30}])"));
  ASSERT_EQ(c.incisions.size(), 1u);
  EXPECT_EQ(c.incisions[0].plug, PlugHandling::keep);
  EXPECT_DOUBLE_EQ(c.incisions[0].radius_mm, 5.0);
  ASSERT_TRUE(c.pattern);
  EXPECT_EQ(*c.pattern->count, 3);
  EXPECT_EQ(c.pattern->seed, 9u);
  EXPECT_EQ(c.pattern->region.kind, IncisionRegion::Kind::sphere);
  EXPECT_DOUBLE_EQ(c.pattern->region.radius_mm, 30.0);
  ASSERT_EQ(c.scalpel_cuts.size(), 1u);
  EXPECT_DOUBLE_EQ(c.scalpel_cuts[0].blade_angle_deg, 30.0);
  EXPECT_EQ(c.scalpel_index[0], 1u);
  ASSERT_EQ(c.flaps.size(), 1u);
  EXPECT_EQ(c.flaps[0].shape, FlapShape::closed);
  EXPECT_EQ(c.flap_index[0], 0u);
  EXPECT_TRUE(parse_case_cuts(case_with("")).empty());
}

TEST(CaseCuts, RefusesBadFieldsByPath) {
  EXPECT_EQ(refusal(R"(, "incisions": {"depth_mm": 4, "at_mm": [[0, 0, 0]]})"),
            "case.json: /incisions/radius_mm is missing; expected a positive incision radius in mm");
  EXPECT_EQ(refusal(R"(, "incisions": {"radius_mm": 5, "depth_mm": 4})"),
            "case.json: /incisions/at_mm is missing; expected incision centres \"at_mm\" or a \"place\" section");
  EXPECT_EQ(refusal(R"(, "incisions": {"radius_mm": 5, "depth_mm": 4, "plug": "drop", "at_mm": []})"),
            "case.json: /incisions/plug is \"drop\"; expected \"remove\" or \"keep\"");
  EXPECT_EQ(refusal(R"(, "cuts": [{"type": "laser", "path_mm": [[0, 0, 0], [1, 0, 0]], "depth_mm": 1}])"),
            "case.json: /cuts/0/type is \"laser\"; expected \"scalpel\" or \"flap\"");
  EXPECT_EQ(refusal(R"(, "cuts": [{"type": "flap", "path_mm": [[0, 0, 0], [1, 0, 0]], "depth_mm": 1}])"),
            "case.json: /cuts/0/path_mm is [[0,0,0],[1,0,0]]; expected an array of at least 3 points [x, y, z] (mm)");
  EXPECT_EQ(refusal(R"(, "cuts": [{"type": "scalpel", "path_mm": [[0, 0, 0], [1, 0, 0]], "depth_mm": -2}])"),
            "case.json: /cuts/0/depth_mm is -2; expected a positive cut depth in mm");
}

}  // namespace
}  // namespace cleave
