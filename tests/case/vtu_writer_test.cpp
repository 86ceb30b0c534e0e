// VTU output: the counts, connectivity order and arrays ParaView reads; NaN is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/vtu_writer.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave {
namespace {

TEST(VtuWriter, WritesCellsPointsAndArraysInVtkHexOrder) {
  const auto lv = LinkedVolume::from_labels(make_builtin_shape("plate", {Vec3i{2, 1, 1}, {}}));
  VolumeFields fields;
  fields.point_data.push_back({"displacement", 3, std::vector<double>(static_cast<size_t>(3 * lv.vertex_count()), 0.5)});
  fields.cell_data.push_back({"label", 1, {1.0, 1.0}});
  const auto file = std::filesystem::temp_directory_path() / "cleave_vtu_test" / "plate.vtu";
  write_vtu(file, lv, fields);
  const std::string text = read_file(file);
  EXPECT_NE(text.find("NumberOfPoints=\"12\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"displacement\" NumberOfComponents=\"3\""), std::string::npos);
  // VTK order (0,0,0) (1,0,0) (1,1,0) (0,1,0) ... = cleave corners 0 1 3 2 4 5 7 6.
  const CellId c = 0;
  std::string expected;
  for (int k : {0, 1, 3, 2, 4, 5, 7, 6}) expected += std::to_string(lv.corner_vertex(c, k)) + " ";
  EXPECT_NE(text.find(expected + "\n"), std::string::npos) << expected;
  EXPECT_NE(text.find("12\n12\n"), std::string::npos);  // two hexahedra
}

TEST(VtuWriter, RefusesWrongSizesAndNonFiniteValues) {
  const auto lv = LinkedVolume::from_labels(make_builtin_shape("plate", {Vec3i{2, 1, 1}, {}}));
  const auto file = std::filesystem::temp_directory_path() / "cleave_vtu_test" / "bad.vtu";
  VolumeFields wrong;
  wrong.cell_data.push_back({"label", 1, {1.0}});
  EXPECT_THROW(write_vtu(file, lv, wrong), InputError);
  VolumeFields nan;
  nan.cell_data.push_back({"stress", 1, {1.0, std::numeric_limits<double>::quiet_NaN()}});
  try {
    write_vtu(file, lv, nan);
    FAIL();
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(), "cell data array 'stress' holds a non-finite value; refusing to write it");
  }
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(AtomicFile, ReplacesContentWithoutLeavingTemporaries) {
  const auto dir = std::filesystem::temp_directory_path() / "cleave_atomic_test";
  std::filesystem::remove_all(dir);
  write_file_atomically(dir / "a.txt", "first");
  write_file_atomically(dir / "a.txt", "second");
  EXPECT_EQ(read_file(dir / "a.txt"), "second");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
  EXPECT_THROW(read_file(dir / "a.txt", 3), InputError);
}

}  // namespace
}  // namespace cleave
