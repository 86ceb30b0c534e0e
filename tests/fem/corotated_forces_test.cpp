// The cells' corotated forces (fem/corotated_forces.hpp): the AVX-512 mode pass equals the dense
// pass, each cell's forces balance, a rigid motion of a stress-free body has none, a pass over
// cell ranges writes those cells only, and sizes that do not fit are refused.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_forces.hpp"
#include "cleave/fem/corotation.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

struct Box {
  TissueModel model = test::make_box_model({7, 5, 3}, 1.5, 60.0, 0.42, [](const Vec3i& v) { return Label(v.x() % 3 == 1 ? 2 : 1); },
                                           {{Label{2}, Material{"stiff", 180.0, 0.3, 1100.0}}});
  ElementTable table;
  std::vector<Vec6> stress;
  Vector u;
  std::vector<Mat3> rotations;
  Box() {
    model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
      const Vec3i v = model.volume.cell_voxel(c);
      return v.x() < 3 && v.y() < 2;
    }));
    table = make_element_table(model);
    stress.resize(static_cast<std::size_t>(model.volume.cell_count()));
    for (std::size_t c = 0; c < stress.size(); ++c) stress[c] << 15.0 + static_cast<double>(c % 7), 6.0, -1.0, 2.0, -0.5, 1.0;
    u = test::turned_displacement(model.volume);
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += 0.05 * std::sin(0.7 * static_cast<double>(i));  // and strained
    cell_rotations(model.volume, u, rotations);
  }
};

TEST(CorotatedForcePass, ModePassEqualsTheDensePassAndEachCellsForcesBalance) {
  const Box box;
  CorotatedForcePass pass;
  pass.set_topology(box.model.volume, box.table);
  if (!pass.mode_pass()) GTEST_SKIP() << "this CPU has no AVX-512 F and DQ: only the dense pass runs";
  for (const bool with_stress : {true, false}) {
    SCOPED_TRACE(with_stress ? "with stress" : "without stress");
    const std::span<const Vec6> stress = with_stress ? std::span<const Vec6>(box.stress) : std::span<const Vec6>();
    std::vector<double> modes, dense;
    pass.per_cell(box.rotations, stress, box.u, modes);
    pass.set_mode_pass(false);
    pass.per_cell(box.rotations, stress, box.u, dense);
    pass.set_mode_pass(true);
    ASSERT_EQ(modes.size(), 24 * static_cast<std::size_t>(box.model.volume.cell_count()));
    const Eigen::Map<const Vector> a(modes.data(), static_cast<Eigen::Index>(modes.size()));
    const Eigen::Map<const Vector> b(dense.data(), static_cast<Eigen::Index>(dense.size()));
    const double scale = b.lpNorm<Eigen::Infinity>();
    ASSERT_GT(scale, 1e-3);
    EXPECT_LE((a - b).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
    // Per cell and component, the 8 corner forces sum to zero (K^e and T^e have no net force).
    for (std::size_t c = 0; c < modes.size() / 24; ++c)
      for (std::size_t i = 0; i < 3; ++i) {
        double sum = 0;
        for (std::size_t k = 0; k < 8; ++k) sum += modes[24 * c + 8 * i + k];
        EXPECT_NEAR(sum, 0.0, 1e-12 * scale);
      }
  }
}

TEST(CorotatedForcePass, ARigidMotionOfAStressFreeBodyHasNoForce) {
  const Box box;
  CorotatedForcePass pass;
  pass.set_topology(box.model.volume, box.table);
  // Turned by 50 degrees and moved: u = (Q - I) X + t.
  const Mat3 turn = Eigen::AngleAxisd(0.87, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  Vector u(3 * static_cast<Eigen::Index>(box.model.volume.vertex_count()));
  for (VertexId v = 0; v < box.model.volume.vertex_count(); ++v) {
    const Vec3 x = box.model.volume.vertex_position_mm(v);
    u.segment<3>(3 * v) = turn * x - x + Vec3(3.0, -1.0, 2.0);
  }
  std::vector<Mat3> rotations;
  cell_rotations(box.model.volume, u, rotations);
  for (const bool mode : {true, false}) {
    if (mode && !pass.mode_pass()) continue;
    pass.set_mode_pass(mode);
    std::vector<double> forces;
    pass.per_cell(rotations, {}, u, forces);
    // Forces of 1 mm of stretch are of order E h = 90-270 mN: none here, to rounding.
    for (const double f : forces) EXPECT_NEAR(f, 0.0, 1e-9);
  }
}

TEST(CorotatedForcePass, SizesThatDoNotFitAreRefused) {
  const Box box;
  CorotatedForcePass pass;
  std::vector<double> forces;
  try {
    pass.per_cell(box.rotations, box.stress, box.u, forces);
    ADD_FAILURE() << "a pass before set_topology ran";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "corotated forces: set_topology must come before a pass");
  }
  pass.set_topology(box.model.volume, box.table);
  try {
    pass.per_cell(box.rotations, std::span<const Vec6>(box.stress).first(3), box.u, forces);
    ADD_FAILURE() << "3 stresses were taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3 stresses"), std::string::npos) << e.what();
  }
}

// Over cell ranges, the pass writes exactly the listed cells' values (those of the whole pass,
// bit for bit) and leaves every other cell's as they were; ranges that do not fit are refused.
TEST(CorotatedForcePass, OverCellRangesOnlyTheListedCellsAreComputed) {
  const Box box;
  CorotatedForcePass pass;
  pass.set_topology(box.model.volume, box.table);
  const auto cells = static_cast<std::size_t>(box.model.volume.cell_count());
  const std::vector<CellRange> ranges = {{0, 3}, {7, 7}, {10, 31}, {cells - 4, cells}};
  for (const bool mode : {true, false}) {
    if (mode && !pass.mode_pass()) continue;
    pass.set_mode_pass(mode);
    SCOPED_TRACE(mode ? "mode pass" : "dense pass");
    std::vector<double> whole;
    pass.per_cell(box.rotations, box.stress, box.u, whole);
    constexpr double kUntouched = -7.25;
    std::vector<double> partial(24 * cells, kUntouched);
    pass.per_cell(box.rotations, box.stress, box.u, ranges, partial);
    std::vector<std::uint8_t> listed(cells, 0);
    for (const auto& [begin, end] : ranges)
      for (std::size_t c = begin; c < end; ++c) listed[c] = 1;
    for (std::size_t c = 0; c < cells; ++c)
      for (std::size_t k = 0; k < 24; ++k)
        EXPECT_EQ(partial[24 * c + k], listed[c] ? whole[24 * c + k] : kUntouched) << "cell " << c << " value " << k;
  }
  std::vector<double> short_buffer(24 * cells - 1, 0.0);
  try {
    pass.per_cell(box.rotations, box.stress, box.u, ranges, short_buffer);
    ADD_FAILURE() << "a buffer one value short was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("corotated forces over cell ranges: {} values for {} cells; expected 24 per cell",
                                                  24 * cells - 1, cells));
  }
  std::vector<double> buffer(24 * cells, 0.0);
  const std::vector<CellRange> past_the_end = {{cells - 2, cells + 1}};
  try {
    pass.per_cell(box.rotations, box.stress, box.u, past_the_end, buffer);
    ADD_FAILURE() << "a range past the last cell was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("corotated forces over cell ranges: range [{}, {}) outside the {} cells", cells - 2,
                                                  cells + 1, cells));
  }
}

}  // namespace
}  // namespace cleave
