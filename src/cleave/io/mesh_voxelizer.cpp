#include "cleave/io/mesh_voxelizer.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <mutex>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/util/NullInterrupter.h>

#include "cleave/core/error.hpp"
#include "cleave/io/grid_covering_box.hpp"

namespace cleave {
namespace {

constexpr int kPaddingCells = 1;            // empty cells around the mesh's bounding box
constexpr float kNarrowBandHalfWidth = 3.0f;  // level-set voxels (half cells) on each side
constexpr double kVoxelizeShare = 0.8;        // progress fraction spent inside OpenVDB
// Inside/outside cell pairs whose distances add up to more than this many cells have no surface
// between them; when more than kMaxFarBoundaryFraction of all pairs are such, nothing is enclosed.
constexpr double kSurfaceCrossingSlack = 1.25;
constexpr double kMaxFarBoundaryFraction = 0.5;
// Some cell centre must lie deeper inside than this (cells): a flat sheet lying on cell centres
// would otherwise count as a one-cell-thick body.
constexpr double kMinEnclosedDepthCells = 0.5;

/// Forwards OpenVDB's percentages to a ProgressFn (OpenVDB may call from worker threads).
class ProgressInterrupter : public openvdb::util::NullInterrupter {
 public:
  explicit ProgressInterrupter(const ProgressFn& progress) : progress_(progress) {}
  bool wasInterrupted(int percent = -1) override {
    if (percent >= 0 && progress_) {
      const std::lock_guard<std::mutex> lock(mutex_);
      progress_("voxelizing mesh", kVoxelizeShare * percent / 100.0);
    }
    return false;
  }

 private:
  const ProgressFn& progress_;
  std::mutex mutex_;
};

/// True when the inside region is bounded by the surface: between an inside and an outside cell
/// the surface must cross, so |d_in| + |d_out| <= h (triangle inequality). An open or flat surface
/// gets a sign from OpenVDB's flood fill on one side only, and most of that region's boundary then
/// lies far from any triangle.
bool boundary_follows_surface(const LabelVolume& volume, const std::vector<float>& centre_distance) {
  const GridSpec& grid = volume.grid;
  std::int64_t faces = 0, far_from_surface = 0;
  for (int z = 0; z < grid.dims.z(); ++z)
    for (int y = 0; y < grid.dims.y(); ++y)
      for (int x = 0; x < grid.dims.x(); ++x) {
        const auto a = static_cast<size_t>(grid.voxel_index({x, y, z}));
        for (const Vec3i& step : {Vec3i(1, 0, 0), Vec3i(0, 1, 0), Vec3i(0, 0, 1)}) {
          const Vec3i other = Vec3i(x, y, z) + step;
          if (!grid.contains_voxel(other)) continue;
          const auto b = static_cast<size_t>(grid.voxel_index(other));
          if ((volume.labels[a] != 0) == (volume.labels[b] != 0)) continue;
          ++faces;
          const double gap = std::abs(static_cast<double>(centre_distance[a])) + std::abs(static_cast<double>(centre_distance[b]));
          if (gap > kSurfaceCrossingSlack * grid.cell_size_mm) ++far_from_surface;
        }
      }
  return static_cast<double>(far_from_surface) <= kMaxFarBoundaryFraction * static_cast<double>(faces);
}

}  // namespace

LabelVolume voxelize_surface_mesh(const TriangleMesh& mesh, const MeshVoxelizeOptions& options) {
  const std::string& f = options.source;
  if (mesh.vertices_mm.empty() || mesh.triangles.empty())
    throw InputError(fmt::format("{}: the mesh has no triangles", f));
  Vec3 lo = mesh.vertices_mm.front(), hi = lo;
  for (const Vec3& p : mesh.vertices_mm) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double h = options.cell_size_mm.value_or((hi - lo).maxCoeff() / kDefaultMeshCellsAlongLargestExtent);
  if (!(h > 0))
    throw InputError(fmt::format("{}: all vertices coincide; the mesh encloses no volume", f));
  const GridSpec grid = grid_covering_box(lo, hi, h, kPaddingCells, fmt::format("{} at cell size {} mm", f, h));
  LabelVolume volume = make_empty_label_volume(grid, /*with_distance=*/true);

  static std::once_flag vdb_initialized;
  std::call_once(vdb_initialized, [] { openvdb::initialize(); });
  report(options.progress, "voxelizing mesh", 0.0);
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices_mm.size());
  for (const Vec3& p : mesh.vertices_mm)
    points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  const auto vertex_count = static_cast<int>(mesh.vertices_mm.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int v : tri)
      if (v < 0 || v >= vertex_count)
        throw InputError(fmt::format("{}: triangle {} refers to vertex {}; the mesh has {} vertices", f, t, v,
                                     vertex_count));
    triangles.emplace_back(static_cast<unsigned>(tri[0]), static_cast<unsigned>(tri[1]), static_cast<unsigned>(tri[2]));
  }
  // Level-set voxel (2x, 2y, 2z) is grid corner (x, y, z); (2x+1, 2y+1, 2z+1) is the centre of cell (x, y, z).
  auto transform = openvdb::math::Transform::createLinearTransform(0.5 * h);
  transform->postTranslate(openvdb::Vec3d(grid.origin_mm.x(), grid.origin_mm.y(), grid.origin_mm.z()));
  ProgressInterrupter interrupter(options.progress);
  const openvdb::FloatGrid::Ptr sdf =
      openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(interrupter, *transform, points, triangles, kNarrowBandHalfWidth);
  const auto accessor = sdf->getConstAccessor();

  std::vector<float> centre_distance(static_cast<size_t>(grid.voxel_count()));
  std::int64_t inside = 0;
  float deepest = 0.0f;  // most negative centre distance (mm)
  for (int z = 0; z <= grid.dims.z(); ++z) {
    report(options.progress, "voxelizing mesh", kVoxelizeShare + (1 - kVoxelizeShare) * z / (grid.dims.z() + 1));
    for (int y = 0; y <= grid.dims.y(); ++y)
      for (int x = 0; x <= grid.dims.x(); ++x) {
        volume.corner_distance_mm[static_cast<size_t>(grid.corner_index({x, y, z}))] =
            accessor.getValue(openvdb::Coord(2 * x, 2 * y, 2 * z));
        if (x < grid.dims.x() && y < grid.dims.y() && z < grid.dims.z()) {
          const auto n = static_cast<size_t>(grid.voxel_index({x, y, z}));
          centre_distance[n] = accessor.getValue(openvdb::Coord(2 * x + 1, 2 * y + 1, 2 * z + 1));
          deepest = std::min(deepest, centre_distance[n]);
          if (centre_distance[n] < 0.0f) {
            volume.labels[n] = 1;
            ++inside;
          }
        }
      }
  }
  const bool has_depth = static_cast<double>(deepest) < -kMinEnclosedDepthCells * h;
  if (inside == 0 || !has_depth || !boundary_follows_surface(volume, centre_distance))
    throw InputError(fmt::format("{}: the mesh encloses no volume at cell size {} mm (an open, flat or degenerate "
                                 "surface has no inside); expected a closed surface thicker than a cell", f, h));
  report(options.progress, "voxelizing mesh", 1.0);
  return volume;
}

}  // namespace cleave
