// The case file: validation errors name the file, the JSON path, the value and what was expected.
#include <gtest/gtest.h>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"

namespace cleave {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_case_text(text, "case.json", ".");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(CaseFile, MinimalCaseUsesDefaults) {
  const CaseFile c = parse_case_text(R"({"model": {"source": "abdomen"}})", "case.json", ".");
  EXPECT_EQ(c.model_source, "abdomen");
  EXPECT_FALSE(c.model_options.resolution.has_value());
  EXPECT_TRUE(c.materials.empty());
  EXPECT_TRUE(c.output.vtu);
}

TEST(CaseFile, ReadsModelMaterialsAndOutput) {
  const CaseFile c = parse_case_text(R"({
    "model": {"source": "cylinder", "resolution": [42, 42, 51]},
    "materials": {"1": {"name": "dermis", "E_kPa": 120, "nu": 0.45, "density_kg_per_m3": 1100}},
    "output": {"surface_gltf": false}
  })", "case.json", ".");
  EXPECT_EQ(*c.model_options.resolution, Vec3i(42, 42, 51));
  EXPECT_EQ(c.materials.at(1).name, "dermis");
  EXPECT_DOUBLE_EQ(c.materials.at(1).youngs_modulus_kPa, 120);
  EXPECT_DOUBLE_EQ(c.materials.at(1).poisson_ratio, 0.45);
  EXPECT_FALSE(c.output.surface_gltf);
}

TEST(CaseFile, RelativeModelPathsResolveAgainstTheCaseFolder) {
  const CaseFile c = parse_case_text(R"({"model": {"source": "scans/head.nii.gz"}})", "case.json", "/data/patient7");
  EXPECT_EQ(c.model_source, "/data/patient7/scans/head.nii.gz");
}

TEST(CaseFile, ErrorsNameThePathValueAndExpectation) {
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen"}, "materials": {"1": {"E_kPa": -5}}})"),
            "case.json: /materials/1/E_kPa is -5; expected a positive Young's modulus in kPa");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen"}, "materials": {"1": {"nu": 0.5}}})"),
            "case.json: /materials/1/nu is 0.5; expected a Poisson ratio in (-1, 0.5)");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen"}, "materials": {"1": {"density_kg_per_m3": 0}}})"),
            "case.json: /materials/1/density_kg_per_m3 is 0; expected a positive density in kg/m^3");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen", "resolution": [10, -2, 4]}})"),
            "case.json: /model/resolution/1 is -2; expected an integer from 1 to 100000");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen", "resolution": [10, 2]}})"),
            "case.json: /model/resolution is [10,2]; expected [NX, NY, NZ] (three positive integers)");
  EXPECT_EQ(error_of(R"({"model": {}})"),
            "case.json: /model/source is missing; expected a built-in shape name or a path to a volume or mesh");
  EXPECT_EQ(error_of(R"({})"), "case.json: /model is missing; expected an object");
  EXPECT_EQ(error_of(R"([1, 2])"),
            "case.json: / is [1,2]; expected a JSON object with at least a \"model\" section");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen", "cell_size": 2}})"),
            "case.json: /model has unknown key 'cell_size'; expected one of: source, resolution, cell_size_mm, labels, "
            "threshold, mesh_scale");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen"}, "materials": {"skin": {}}})"),
            "case.json: /materials: key 'skin' is not a label; expected a label number from 1 to 255");
  EXPECT_EQ(error_of(R"({"model": {"source": "abdomen"}, "output": {"vtu": "yes"}})"),
            "case.json: /output/vtu is \"yes\"; expected true or false");
}

TEST(CaseFile, UnknownSectionsAreRefusedWithTheList) {
  const std::string e = error_of(R"({"model": {"source": "abdomen"}, "desing": {}})");
  EXPECT_EQ(e.rfind("case.json: / has unknown section 'desing'; expected one of: cleave_case, model,", 0), 0u) << e;
}

TEST(CaseFile, SyntaxErrorsSayWhere) {
  const std::string e = error_of("{\"model\": {\"source\": \"abdomen\"},}");
  EXPECT_EQ(e.rfind("case.json: invalid JSON at byte 33: syntax error", 0), 0u) << e;
}

TEST(CaseFile, DeeplyNestedJsonIsRefusedWithoutRecursionTrouble) {
  std::string deep(100000, '[');
  deep += std::string(100000, ']');
  EXPECT_EQ(error_of(deep), "case.json: JSON nested deeper than 64 levels");
}

TEST(CaseFile, MissingFileIsNamed) {
  try {
    load_case_file("/nonexistent/case.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/case.json: no such file");
  }
}

}  // namespace
}  // namespace cleave
