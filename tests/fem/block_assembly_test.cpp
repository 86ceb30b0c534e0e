// The dynamics assembles its system straight into block CSR (VertexBlockGather) and eliminates
// fixed dofs there; both must equal, entry by entry, the scalar CSR assembly and elimination they
// replace, on a cut body (divided vertices, several pieces) with a deformed, rotated state.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

/// A two-material box with a cut that frees a corner block: divided vertices, two pieces.
TissueModel cut_two_material_box() {
  TissueModel model = test::make_box_model({5, 4, 3}, 1.5, 60.0, 0.42, [](const Vec3i& v) { return Label(v.z() >= 1 ? 2 : 1); },
                                           {{Label{2}, Material{"stiff", 180.0, 0.3, 1100.0}}});
  const VertexId before = model.volume.vertex_count();
  model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() < 2 && v.y() < 2;
  }));
  EXPECT_GT(model.volume.vertex_count(), before);
  return model;
}

/// Per cell, the rotation of a turned and wobbled state (not the identity anywhere).
std::vector<Mat3> turned_rotations(const LinkedVolume& volume) {
  std::vector<Mat3> rotations;
  cell_rotations(volume, test::turned_displacement(volume), rotations);
  return rotations;
}

/// The largest |a_ij - b_ij| over the scalar pattern of `a`, reading b's block values.
double largest_difference(const SparseMatrix& a, const BlockSparseMatrix<double>& b) {
  SparseMatrix from_blocks = a;
  copy_block_values(b, from_blocks);
  double out = 0;
  for (Eigen::Index k = 0; k < a.nonZeros(); ++k) out = std::max(out, std::abs(a.valuePtr()[k] - from_blocks.valuePtr()[k]));
  return out;
}

TEST(BlockAssembly, GatherIntoBlocksEqualsTheScalarGatherOnACutBody) {
  const TissueModel model = cut_two_material_box();
  const LinkedVolume& volume = model.volume;
  const std::vector<Mat3> rotations = turned_rotations(volume);
  const ElementTable table = make_element_table(model);
  volume.vertex_cells();
  const auto block = [&](CellId c, int a, int b) -> Mat3 {
    const Mat3& r = rotations[static_cast<std::size_t>(c)];
    return 2.5 * r * table.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b) * r.transpose();
  };
  SparseMatrix scalar = make_vertex_block_pattern(volume);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) gather_vertex_rows(volume, v, block, scalar);
  BlockSparseMatrix<double> blocks = to_block_sparse<double>(make_vertex_block_pattern(volume));
  std::fill(blocks.values.begin(), blocks.values.end(), 7.0);  // the gather overwrites, not adds
  const VertexBlockGather gather = make_vertex_block_gather(volume, blocks);
  ASSERT_EQ(gather.first_slot.back(), 8 * volume.cell_count());  // one slot per (cell, corner)
  for (VertexId v = 0; v < volume.vertex_count(); ++v) gather_vertex_block_row(volume, v, gather, block, blocks);
  double largest = 0;
  for (Eigen::Index k = 0; k < scalar.nonZeros(); ++k) largest = std::max(largest, std::abs(scalar.valuePtr()[k]));
  ASSERT_GT(largest, 1.0);
  EXPECT_EQ(largest_difference(scalar, blocks), 0.0);
  // Every block of the pattern was written (none keeps the 7.0 it started with).
  EXPECT_EQ(std::count(blocks.values.begin(), blocks.values.end(), 7.0), 0);
}

TEST(BlockAssembly, GatherTableNamesAMissingBlock) {
  const TissueModel model = cut_two_material_box();
  BlockSparseMatrix<double> blocks = to_block_sparse<double>(make_vertex_block_pattern(model.volume));
  // Drop the last block of row 0 from the pattern: the table must refuse it, naming both vertices.
  const std::int32_t missing = blocks.column[static_cast<std::size_t>(blocks.row_start[1]) - 1];
  blocks.column[static_cast<std::size_t>(blocks.row_start[1]) - 1] = missing + 100000;
  try {
    (void)make_vertex_block_gather(model.volume, blocks);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), fmt::format("vertex block gather: vertex 0 shares a cell with {}, but the matrix has no block (0, {})",
                                                 missing, missing));
  }
}

TEST(BlockAssembly, FixedDofEliminationOnBlocksEqualsTheScalarOne) {
  const TissueModel model = cut_two_material_box();
  const LinkedVolume& volume = model.volume;
  const ElementTable table = make_element_table(model);
  volume.vertex_cells();
  const auto block = [&](CellId c, int a, int b) -> Mat3 { return table.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b); };
  SparseMatrix scalar = make_vertex_block_pattern(volume);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) gather_vertex_rows(volume, v, block, scalar);
  BlockSparseMatrix<double> blocks = to_block_sparse<double>(scalar);
  // Whole vertices held at a prescribed displacement, and single axes of others.
  std::vector<VertexId> held;
  std::vector<Vec3> moved;
  for (VertexId v = 0; v < volume.vertex_count(); v += 7) {
    held.push_back(v);
    moved.emplace_back(0.1 * v, -0.05, 0.02 * (v % 3));
  }
  FixedDofs fixed = fix_vertices(volume.vertex_count(), held, moved);
  for (VertexId v = 3; v < volume.vertex_count(); v += 11) {
    fixed.fixed[static_cast<std::size_t>(3 * v + 1)] = 1;
    fixed.value_mm[3 * v + 1] = 0.3;
  }
  const auto n = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  Vector b_scalar(n);
  for (Eigen::Index i = 0; i < n; ++i) b_scalar[i] = std::sin(0.37 * static_cast<double>(i));
  Vector b_blocks = b_scalar;
  eliminate_fixed_dofs(scalar, b_scalar, fixed);
  eliminate_fixed_dofs(blocks, b_blocks, fixed);
  EXPECT_EQ(largest_difference(scalar, blocks), 0.0);
  EXPECT_LE((b_scalar - b_blocks).lpNorm<Eigen::Infinity>(), 1e-14 * b_scalar.lpNorm<Eigen::Infinity>());
  // The eliminated system is what the solvers expect: identity rows with the prescribed value.
  EXPECT_EQ(b_blocks[3 * 7 + 0], moved[1].x());  // vertex 7 is the second held one
  EXPECT_EQ(b_blocks[3 * 3 + 1], 0.3);
}

// The dynamic step's block pattern is made without scalar CSR and, after a cut, patched in place
// (rows of untouched vertices copied): both must be exactly the block pattern of the scalar one.
TEST(BlockAssembly, BlockPatternAndItsRepatchAfterACutEqualTheScalarPattern) {
  TissueModel model = test::make_box_model({10, 8, 4}, 1.5, 60.0, 0.42);
  LinkedVolume& volume = model.volume;
  BlockSparseMatrix<double> blocks = make_vertex_block_csr(volume);
  const BlockSparseMatrix<double> from_scalar = to_block_sparse<double>(make_vertex_block_pattern(volume));
  EXPECT_EQ(blocks.row_start, from_scalar.row_start);
  EXPECT_EQ(blocks.column, from_scalar.column);
  ASSERT_EQ(blocks.values.size(), 9 * blocks.blocks());
  EXPECT_EQ(std::count(blocks.values.begin(), blocks.values.end(), 0.0), static_cast<std::ptrdiff_t>(blocks.values.size()));
  // Two cuts, the second through vertices the first divided: each repatch sees the rows its own
  // cut touched (the dynamics passes the union of all cuts since its last pattern).
  std::vector<std::uint8_t> affected;
  for (const int depth : {2, 3}) {
    const VertexId before = volume.vertex_count();
    const CutReport report = volume.cut_links(test::faces_between(volume, [&](CellId c) {
      const Vec3i v = volume.cell_voxel(c);
      return v.x() < depth && v.y() < 2;
    }));
    ASSERT_GT(volume.vertex_count(), before);
    const std::vector<std::uint8_t> touched = vertices_affected_by_cut(volume, report);
    affected.resize(touched.size(), 0);
    for (std::size_t v = 0; v < touched.size(); ++v) affected[v] |= touched[v];
  }
  ASSERT_LT(std::count(affected.begin(), affected.end(), std::uint8_t{1}), static_cast<std::ptrdiff_t>(affected.size()) / 3);
  repattern_vertex_block_csr(volume, blocks, affected);
  const BlockSparseMatrix<double> cut_from_scalar = to_block_sparse<double>(make_vertex_block_pattern(volume));
  EXPECT_EQ(blocks.row_start, cut_from_scalar.row_start);
  EXPECT_EQ(blocks.column, cut_from_scalar.column);
  EXPECT_EQ(blocks.values.size(), 9 * blocks.blocks());
}

}  // namespace
}  // namespace cleave
