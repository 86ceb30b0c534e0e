// The sides of the body's surface and the support {"surface": "inner"} of the case section
// "simulation.fixed": a shell is held on its deep face, the skin stays free.
#include <gtest/gtest.h>

#include <cmath>

#include "cleave/core/error.hpp"
#include "cleave/cut/surface_side_vertices.hpp"
#include "cleave/io/case_mechanics.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cut_test_models.hpp"

namespace cleave {
namespace {

TEST(SurfaceSideVertices, TubeInnerSideIsTheBoreAndOuterSideTheSkinAndEnds) {
  // The built-in tube: outer radius 42 mm, inner radius 0.615 * 42 = 25.8 mm, axis along z at (42, 42).
  const TissueModel tube = make_tissue_model("cylinder", make_builtin_shape("cylinder"));
  const BodySurface surface(tube);
  const double h = tube.volume.grid().cell_size_mm;
  const double length = tube.volume.grid().extent_mm().z();
  const std::vector<VertexId> inner = surface_side_vertices(surface, SurfaceSide::inner);
  const std::vector<VertexId> outer = surface_side_vertices(surface, SurfaceSide::outer);
  ASSERT_FALSE(inner.empty());
  ASSERT_FALSE(outer.empty());
  const auto radius = [&](VertexId v) {
    const Vec3 p = tube.volume.vertex_position_mm(v);
    return std::hypot(p.x() - 42.0, p.y() - 42.0);
  };
  for (const VertexId v : inner) EXPECT_LT(radius(v), 0.615 * 42.0 + 1.5 * h) << "vertex " << v;
  for (const VertexId v : outer) {
    const double z = tube.volume.vertex_position_mm(v).z();
    const bool on_end = z <= 0.0 || z >= length;
    EXPECT_TRUE(on_end || radius(v) > 42.0 - 1.5 * h) << "vertex " << v;
  }
  // Every boundary vertex is on one side or the other (both at the bore's rim at the tube's ends).
  EXPECT_LE(surface_side_vertices(surface, SurfaceSide::all).size(), inner.size() + outer.size());
}

TEST(SurfaceSideVertices, PlateHasNoInnerSide) {
  const TissueModel plate = test::make_box({8, 8, 2}, 2.5);
  EXPECT_TRUE(surface_side_vertices(BodySurface(plate), SurfaceSide::inner).empty());
}

SimulationSettings simulation(const std::string& fixed) {
  return parse_simulation_settings(
      parse_case_text(R"({"model": {"source": "plate"}, "simulation": {"fixed": )" + fixed + "}}", "case.json", "."));
}

TEST(CaseFixedSurface, InnerSurfaceIsReadAloneOrBesideBoxesAndOtherSidesAreRefused) {
  const SimulationSettings alone = simulation(R"({"surface": "inner"})");
  EXPECT_TRUE(alone.fixed_boxes.empty());
  ASSERT_EQ(alone.fixed_surfaces.size(), 1u);
  EXPECT_EQ(alone.fixed_surfaces[0], FixedSurface::inner);
  const SimulationSettings both = simulation(R"([{"box_mm": [[0, 0, 0], [5, 100, 10]]}, {"surface": "inner"}])");
  EXPECT_EQ(both.fixed_boxes.size(), 1u);
  EXPECT_EQ(both.fixed_surfaces.size(), 1u);
  try {
    simulation(R"([{"surface": "outer"}])");
    ADD_FAILURE() << "\"outer\" was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "case.json: /simulation/fixed/0/surface is \"outer\"; expected \"inner\"");
  }
  EXPECT_THROW(simulation(R"({"surface": "inner", "box_mm": [[0, 0, 0], [1, 1, 1]]})"), InputError);
}

}  // namespace
}  // namespace cleave
