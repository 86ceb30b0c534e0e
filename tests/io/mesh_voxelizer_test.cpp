// Surface meshes: reading OBJ/STL/PLY/OFF, voxelizing with OpenVDB (volume of a sphere, sub-cell
// corner distances, tolerance to holes), the real CGAL man.off body mesh, and bad meshes.
#include <gmock/gmock.h>
#include <iostream>
#include <gtest/gtest.h>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/io/mesh_voxelizer.hpp"
#include "cleave/io/model_source.hpp"
#include "io_fixtures.hpp"

namespace cleave {
namespace {

using test::TempFolder;
using ::testing::HasSubstr;

constexpr double kRadiusMm = 50.0;
constexpr int kCellsPerDiameter = 20;
const Vec3 kCentreMm{3.3, -1.7, 2.1};  // off the grid's symmetry planes

double sphere_volume(double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r; }

double voxel_volume_mm3(const LabelVolume& v) {
  return static_cast<double>(v.inside_count()) * std::pow(v.grid.cell_size_mm, 3);
}

using test::input_error_of;

struct MeshFormat {
  std::string extension;
  std::string (*write)(const TriangleMesh&);
};

class SphereInEachFormat : public ::testing::TestWithParam<MeshFormat> {};

TEST_P(SphereInEachFormat, VolumeWithinTwoPercentAtTwentyCellsPerDiameter) {
  TempFolder tmp;
  const TriangleMesh sphere = test::icosphere(kCentreMm, kRadiusMm, 4);
  const auto file = tmp / ("sphere" + GetParam().extension);
  test::write_bytes(file, GetParam().write(sphere));

  const TriangleMesh read = read_surface_mesh(file, 1.0);
  EXPECT_EQ(read.triangles.size(), 5120u);
  EXPECT_EQ(read.vertices_mm.size(), 2562u) << "identical vertices are merged";

  ModelSourceOptions options;
  options.cell_size_mm = 2 * kRadiusMm / kCellsPerDiameter;
  const LabelVolume v = load_model_source(file.string(), options);
  const double relative_error = voxel_volume_mm3(v) / sphere_volume(kRadiusMm) - 1.0;
  EXPECT_LT(std::abs(relative_error), 0.02) << "voxel volume " << voxel_volume_mm3(v) << " mm^3";
  // The grid covers the sphere's bounding box plus one empty cell on each side.
  EXPECT_EQ(v.grid.dims, Vec3i::Constant(kCellsPerDiameter + 2));
  EXPECT_EQ(LinkedVolume::from_labels(v).component_count(), 1);
}

INSTANTIATE_TEST_SUITE_P(Formats, SphereInEachFormat,
                         ::testing::Values(MeshFormat{".obj", test::to_obj}, MeshFormat{".stl", test::to_binary_stl},
                                           MeshFormat{".ply", test::to_ascii_ply}, MeshFormat{".off", test::to_off}),
                         [](const auto& p) { return p.param.extension.substr(1); });

TEST(MeshVoxelizer, CornerDistancesAreTheSignedDistanceToTheSurface) {
  const TriangleMesh sphere = test::icosphere(kCentreMm, kRadiusMm, 4);
  const double h = 2 * kRadiusMm / kCellsPerDiameter;
  const LabelVolume v = voxelize_surface_mesh(sphere, {h, "sphere", {}});
  ASSERT_TRUE(v.has_distance());
  int near_surface = 0;
  for (int z = 0; z <= v.grid.dims.z(); ++z)
    for (int y = 0; y <= v.grid.dims.y(); ++y)
      for (int x = 0; x <= v.grid.dims.x(); ++x) {
        const Vec3 p = v.grid.corner_position_mm({x, y, z});
        const double exact = (p - kCentreMm).norm() - kRadiusMm;
        const double d = static_cast<double>(v.corner_distance_mm[static_cast<size_t>(v.grid.corner_index({x, y, z}))]);
        if (std::abs(exact) < h) {
          ++near_surface;
          // Faceting of the level-4 icosphere is 0.3 mm; sub-cell accuracy means far below h = 5 mm.
          EXPECT_NEAR(d, exact, 0.1 * h) << "corner " << x << "," << y << "," << z;
        } else {
          EXPECT_EQ(d < 0, exact < 0) << "sign at corner " << x << "," << y << "," << z;
        }
      }
  EXPECT_GT(near_surface, 500);
}

TEST(MeshVoxelizer, ToleratesSmallHoles) {
  TriangleMesh sphere = test::icosphere(kCentreMm, kRadiusMm, 4);
  // Remove 6 triangles spread over the surface (each about 2.5 mm across, half a cell).
  for (size_t k = 0; k < 6; ++k) sphere.triangles.erase(sphere.triangles.begin() + static_cast<long>(800 * k + 17));
  const LabelVolume v = voxelize_surface_mesh(sphere, {2 * kRadiusMm / kCellsPerDiameter, "holey sphere", {}});
  EXPECT_LT(std::abs(voxel_volume_mm3(v) / sphere_volume(kRadiusMm) - 1.0), 0.02);
}

TEST(MeshVoxelizer, ToleratesInconsistentOrientationAndDuplicatedTriangles) {
  TriangleMesh sphere = test::icosphere(kCentreMm, kRadiusMm, 4);
  for (size_t t = 0; t < sphere.triangles.size(); t += 3) std::swap(sphere.triangles[t][0], sphere.triangles[t][1]);
  sphere.triangles.push_back(sphere.triangles[5]);  // a non-manifold edge
  const LabelVolume v = voxelize_surface_mesh(sphere, {2 * kRadiusMm / kCellsPerDiameter, "flipped sphere", {}});
  EXPECT_LT(std::abs(voxel_volume_mm3(v) / sphere_volume(kRadiusMm) - 1.0), 0.02);
}

TEST(MeshVoxelizer, MeshScaleMultipliesCoordinatesAndDefaultCellSizeGives64CellsAcross) {
  TempFolder tmp;
  const auto file = tmp / "unit_sphere.off";
  test::write_bytes(file, test::to_off(test::icosphere({0, 0, 0}, 0.5, 3)));
  ModelSourceOptions options;
  options.mesh_scale = 200.0;  // diameter 1 -> 200 mm
  const LabelVolume v = load_model_source(file.string(), options);
  EXPECT_NEAR(v.grid.cell_size_mm, 200.0 / kDefaultMeshCellsAlongLargestExtent, 1e-3);
  EXPECT_EQ(v.grid.dims, Vec3i::Constant(kDefaultMeshCellsAlongLargestExtent + 2));
  EXPECT_NEAR(voxel_volume_mm3(v) / sphere_volume(100.0), 1.0, 0.02);
}

// ---------------------------------------------------------------------------------------------
// The real body mesh from CGAL's data (libcgal-demo): height 1, scaled to 1750 mm.

TEST(RealData, CgalManOffIsABodySizedClosedVolume) {
  TempFolder tmp;
  const auto man = test::extract_cgal_man(tmp.path);
  ASSERT_FALSE(man.empty());
  ModelSourceOptions options;
  options.mesh_scale = 1750.0;
  options.cell_size_mm = 10.0;
  const LabelVolume v = load_model_source(man.string(), options);
  const LinkedVolume linked = LinkedVolume::from_labels(v);
  Vec3 lo = Vec3::Constant(1e30), hi = -lo;
  for (CellId c = 0; c < linked.cell_count(); ++c) {
    lo = lo.cwiseMin(linked.cell_center_mm(c));
    hi = hi.cwiseMax(linked.cell_center_mm(c));
  }
  const Vec3 extent = hi - lo + Vec3::Constant(10.0);
  std::array<double, 3> sorted{extent.x(), extent.y(), extent.z()};
  std::sort(sorted.begin(), sorted.end());
  // Standing body: 1750 mm tall (to a cell), shoulders/arms 300-1800 mm wide, 150-600 mm deep
  // (this mesh measures 740 x 520 x 1750 mm: arms held away from the body).
  EXPECT_NEAR(sorted[2], 1750.0, 20.0);
  EXPECT_GT(sorted[1], 300.0);
  EXPECT_LT(sorted[0], 600.0);
  EXPECT_GT(sorted[0], 150.0);
  // A 1.75 m adult of 55-90 kg at ~1 kg/L tissue density: 55-90 litres (1 L = 1e6 mm^3).
  const double litres = voxel_volume_mm3(v) / 1e6;
  EXPECT_GT(litres, 55.0);
  EXPECT_LT(litres, 90.0);
  std::vector<int> sizes(static_cast<size_t>(linked.component_count()), 0);
  for (int c : linked.cell_components()) ++sizes[static_cast<size_t>(c)];
  const int largest = *std::max_element(sizes.begin(), sizes.end());
  EXPECT_GT(largest, 0.99 * linked.cell_count()) << "one body; at 10 mm thin fingertips may come apart";
  std::cout << "man.off at 10 mm: " << linked.cell_count() << " cells, " << litres << " L, extent " << extent.transpose()
            << " mm, " << linked.component_count() << " components, largest " << largest << "\n";
}

TEST(RealData, CgalManOffRefusesAGridThatWouldNotFit) {
  TempFolder tmp;
  const auto man = test::extract_cgal_man(tmp.path);
  ASSERT_FALSE(man.empty());
  ModelSourceOptions options;
  options.mesh_scale = 1750.0;
  options.cell_size_mm = 0.001;
  const std::string message = input_error_of([&] { load_model_source(man.string(), options); });
  EXPECT_THAT(message, HasSubstr(man.string() + " at cell size 0.001 mm (a "));
  EXPECT_THAT(message, HasSubstr("x1750002 grid)")) << "1750 mm tall plus a padding cell on each side";
  EXPECT_THAT(message, HasSubstr("would need"));
  EXPECT_THAT(message, HasSubstr("choose a larger cell size"));
}

// ---------------------------------------------------------------------------------------------
// Bad meshes: one clear line naming the file and the problem.

TEST(BadMesh, MissingFile) {
  EXPECT_EQ(input_error_of([] { read_surface_mesh("/nonexistent/body.obj", 1.0); }), "/nonexistent/body.obj: no such file");
}

TEST(BadMesh, MalformedObj) {
  TempFolder tmp;
  const auto file = tmp / "garbage.obj";
  test::write_bytes(file, "v 0 0 0\nv 1 0 0\nf 1 2 99\n");
  EXPECT_THAT(input_error_of([&] { read_surface_mesh(file, 1.0); }), HasSubstr(file.string() + ": cannot read the mesh: "));
}

TEST(BadMesh, TruncatedBinaryStl) {
  TempFolder tmp;
  const auto file = tmp / "truncated.stl";
  const std::string full = test::to_binary_stl(test::icosphere({0, 0, 0}, 1.0, 2));
  test::write_bytes(file, full.substr(0, full.size() / 2));
  EXPECT_THAT(input_error_of([&] { read_surface_mesh(file, 1.0); }), HasSubstr(file.string() + ": cannot read the mesh: "));
}

TEST(BadMesh, TruncatedOff) {
  TempFolder tmp;
  const auto file = tmp / "truncated.off";
  test::write_bytes(file, "OFF\n4 4 0\n0 0 0\n1 0 0\n");
  EXPECT_EQ(input_error_of([&] { read_surface_mesh(file, 1.0); }),
            file.string() + ": the file ends at line 4 while expecting a vertex (truncated?)");
}

TEST(BadMesh, OffFaceIndexOutOfRangeAndBadNumber) {
  TempFolder tmp;
  const auto file = tmp / "bad_index.off";
  test::write_bytes(file, "OFF\n# a comment\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_EQ(input_error_of([&] { read_surface_mesh(file, 1.0); }),
            file.string() + ": line 7: face 0 refers to vertex 7; the file has 3 vertices");
  test::write_bytes(file, "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(input_error_of([&] { read_surface_mesh(file, 1.0); }), file.string() + ": line 4: 'zero' is not a valid coordinate");
}

TEST(BadMesh, NanCoordinateInOff) {
  TempFolder tmp;
  const auto file = tmp / "nan.off";
  test::write_bytes(file, "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(input_error_of([&] { read_surface_mesh(file, 1.0); }),
            file.string() + ": vertex 1 is (1, nan, 0); expected finite coordinates");
}

TEST(BadMesh, NanCoordinate) {
  TempFolder tmp;
  const auto file = tmp / "nan.stl";
  TriangleMesh m = test::icosphere({0, 0, 0}, 1.0, 1);
  m.vertices_mm[3].y() = std::numeric_limits<double>::quiet_NaN();
  test::write_bytes(file, test::to_binary_stl(m));
  const std::string message = input_error_of([&] { read_surface_mesh(file, 1.0); });
  EXPECT_THAT(message, HasSubstr(file.string() + ": vertex "));
  EXPECT_THAT(message, HasSubstr("nan"));
  EXPECT_THAT(message, HasSubstr("expected finite coordinates"));
}

TEST(BadMesh, FlatOpenSquareEnclosesNothing) {
  TempFolder tmp;
  const auto file = tmp / "flat.obj";
  test::write_bytes(file, "v 0 0 0\nv 100 0 0\nv 100 100 0\nv 0 100 0\nf 1 2 3\nf 1 3 4\n");
  ModelSourceOptions options;
  options.cell_size_mm = 5.0;
  EXPECT_EQ(input_error_of([&] { load_model_source(file.string(), options); }),
            file.string() + ": the mesh encloses no volume at cell size 5 mm (an open, flat or degenerate surface "
                            "has no inside); expected a closed surface thicker than a cell");
}

TEST(BadMesh, AllVerticesCoincide) {
  TriangleMesh m;
  m.vertices_mm = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  m.triangles = {{0, 1, 2}};
  EXPECT_EQ(input_error_of([&] { voxelize_surface_mesh(m, {std::nullopt, "point.obj", {}}); }),
            "point.obj: all vertices coincide; the mesh encloses no volume");
}

TEST(BadMesh, NonPositiveScale) {
  EXPECT_EQ(input_error_of([] { read_surface_mesh("any.obj", -2.0); }),
            "any.obj: mesh scale -2; expected a positive finite factor");
}

TEST(BadMesh, LabelsDoNotApplyToMeshes) {
  ModelSourceOptions options;
  options.labels = {2};
  EXPECT_EQ(input_error_of([&] { load_model_source("body.obj", options); }),
            "body.obj: labels and thresholds select parts of volumes; a mesh has none");
}

}  // namespace
}  // namespace cleave
