#include "cleave/grid/linked_volume.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <numeric>

#include "cleave/core/error.hpp"

namespace cleave {

Vec3i face_step(Face f) {
  Vec3i step = Vec3i::Zero();
  step[f / 2] = (f & 1) ? 1 : -1;
  return step;
}

std::array<int, 4> face_corners(Face f) {
  const int axis = f / 2;
  const int side = f & 1;
  std::array<int, 4> corners{};
  int n = 0;
  for (int c = 0; c < kCornerCount; ++c)
    if (((c >> axis) & 1) == side) corners[static_cast<size_t>(n++)] = c;
  return corners;
}

namespace {

/// Union-find over the (at most) 8 cells around one grid corner.
struct CornerGroups {
  std::array<int, 8> parent{0, 1, 2, 3, 4, 5, 6, 7};
  int find(int k) {
    while (parent[static_cast<size_t>(k)] != k) k = parent[static_cast<size_t>(k)] = parent[static_cast<size_t>(parent[static_cast<size_t>(k)])];
    return k;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

LinkedVolume LinkedVolume::from_labels(const LabelVolume& volume) {
  LinkedVolume lv;
  lv.grid_ = volume.grid;
  const GridSpec& grid = volume.grid;
  if (volume.labels.size() != static_cast<size_t>(grid.voxel_count()))
    throw InputError(fmt::format("label volume holds {} labels for a {}x{}x{} grid; expected {}", volume.labels.size(),
                                 grid.dims.x(), grid.dims.y(), grid.dims.z(), grid.voxel_count()));
  lv.voxel_to_cell_.assign(volume.labels.size(), kNone);
  for (int z = 0; z < grid.dims.z(); ++z)
    for (int y = 0; y < grid.dims.y(); ++y)
      for (int x = 0; x < grid.dims.x(); ++x) {
        const Vec3i v{x, y, z};
        const auto index = static_cast<size_t>(grid.voxel_index(v));
        if (volume.labels[index] == 0) continue;
        lv.voxel_to_cell_[index] = static_cast<CellId>(lv.voxel_.size());
        lv.voxel_.push_back(v);
        lv.label_.push_back(volume.labels[index]);
      }
  if (lv.voxel_.empty()) throw InputError("the model has no cell inside the body (empty mask or shape)");

  const auto cells = lv.voxel_.size();
  lv.neighbor_.resize(cells);
  lv.cut_mask_.assign(cells, 0);
  lv.corner_vertex_.assign(cells, std::array<VertexId, 8>{kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone});
  for (size_t c = 0; c < cells; ++c)
    for (Face f = 0; f < kFaceCount; ++f)
      lv.neighbor_[c][static_cast<size_t>(f)] = lv.cell_at_voxel(lv.voxel_[c] + face_step(f));

  CutReport ignored;
  for (int z = 0; z <= grid.dims.z(); ++z)
    for (int y = 0; y <= grid.dims.y(); ++y)
      for (int x = 0; x <= grid.dims.x(); ++x) lv.regroup_corner({x, y, z}, ignored);
  return lv;
}

CellId LinkedVolume::cell_at_voxel(const Vec3i& v) const {
  if (!grid_.contains_voxel(v)) return kNone;
  return voxel_to_cell_[static_cast<size_t>(grid_.voxel_index(v))];
}

std::int64_t LinkedVolume::link_count() const {
  std::int64_t n = 0;
  for (CellId c = 0; c < cell_count(); ++c)
    for (Face f = 1; f < kFaceCount; f += 2) n += linked(c, f) ? 1 : 0;
  return n;
}

std::int64_t LinkedVolume::cut_link_count() const {
  std::int64_t n = 0;
  for (CellId c = 0; c < cell_count(); ++c)
    for (Face f = 1; f < kFaceCount; f += 2) n += (neighbor(c, f) != kNone && is_cut(c, f)) ? 1 : 0;
  return n;
}

void LinkedVolume::regroup_corner(const Vec3i& g, CutReport& report) {
  std::array<CellId, 8> cells{};
  bool any = false;
  for (int k = 0; k < kCornerCount; ++k) {
    cells[static_cast<size_t>(k)] = cell_at_voxel(g - corner_offset(k));
    any = any || cells[static_cast<size_t>(k)] != kNone;
  }
  if (!any) return;

  // Cells k and k ^ (1 << axis) share a face; seen from cell k that face is 2 * axis + bit.
  CornerGroups groups;
  for (int k = 0; k < kCornerCount; ++k) {
    const CellId a = cells[static_cast<size_t>(k)];
    if (a == kNone) continue;
    for (int axis = 0; axis < 3; ++axis) {
      const int other = k ^ (1 << axis);
      if (other < k || cells[static_cast<size_t>(other)] == kNone) continue;
      if (linked(a, 2 * axis + ((k >> axis) & 1))) groups.unite(k, other);
    }
  }

  std::array<VertexId, 8> claimed{kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone};
  int claimed_count = 0;
  for (int root = 0; root < kCornerCount; ++root) {
    if (cells[static_cast<size_t>(root)] == kNone || groups.find(root) != root) continue;
    const VertexId old = corner_vertex_[static_cast<size_t>(cells[static_cast<size_t>(root)])][static_cast<size_t>(root)];
    const bool already_claimed =
        std::find(claimed.begin(), claimed.begin() + claimed_count, old) != claimed.begin() + claimed_count;
    VertexId id = old;
    if (old == kNone || already_claimed) {
      id = static_cast<VertexId>(vertex_corner_.size());
      vertex_corner_.push_back(g);
      vertex_cells_valid_ = false;
      if (old != kNone) {
        auto it = std::find_if(report.splits.begin(), report.splits.end(),
                               [old](const VertexSplit& s) { return s.original == old; });
        if (it == report.splits.end()) it = report.splits.insert(report.splits.end(), VertexSplit{old, {}});
        it->created.push_back(id);
      }
    } else {
      claimed[static_cast<size_t>(claimed_count++)] = old;
    }
    for (int k = 0; k < kCornerCount; ++k) {
      const CellId c = cells[static_cast<size_t>(k)];
      if (c == kNone || groups.find(k) != root) continue;
      VertexId& slot = corner_vertex_[static_cast<size_t>(c)][static_cast<size_t>(k)];
      if (slot != id && slot != kNone) report.touched_cells.push_back(c);
      slot = id;
    }
  }
}

CutReport LinkedVolume::cut_links(std::span<const CellFace> links) {
  CutReport report;
  std::vector<std::int64_t> corners;
  for (const CellFace& link : links) {
    if (link.cell < 0 || link.cell >= cell_count() || link.face < 0 || link.face >= kFaceCount)
      throw InputError(fmt::format("cut link (cell {}, face {}) does not exist; expected a cell below {} and a face 0..5",
                                   link.cell, link.face, cell_count()));
    const CellId other = neighbor(link.cell, link.face);
    if (other == kNone || is_cut(link.cell, link.face)) continue;
    cut_mask_[static_cast<size_t>(link.cell)] |= static_cast<std::uint8_t>(1u << link.face);
    cut_mask_[static_cast<size_t>(other)] |= static_cast<std::uint8_t>(1u << opposite(link.face));
    ++report.links_cut;
    report.touched_cells.push_back(link.cell);
    report.touched_cells.push_back(other);
    for (int corner : face_corners(link.face))
      corners.push_back(grid_.corner_index(cell_voxel(link.cell) + corner_offset(corner)));
  }
  if (report.links_cut == 0) return report;
  components_valid_ = false;
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const std::int64_t nx = grid_.dims.x() + 1;
  const std::int64_t ny = grid_.dims.y() + 1;
  for (std::int64_t index : corners) {
    const Vec3i g{static_cast<int>(index % nx), static_cast<int>((index / nx) % ny), static_cast<int>(index / (nx * ny))};
    regroup_corner(g, report);
  }
  std::sort(report.touched_cells.begin(), report.touched_cells.end());
  report.touched_cells.erase(std::unique(report.touched_cells.begin(), report.touched_cells.end()),
                             report.touched_cells.end());
  return report;
}

const std::vector<std::vector<CellId>>& LinkedVolume::vertex_cells() const {
  if (!vertex_cells_valid_ || vertex_cells_.size() != vertex_corner_.size()) {
    vertex_cells_.assign(vertex_corner_.size(), {});
    for (CellId c = 0; c < cell_count(); ++c)
      for (VertexId v : cell_vertices(c)) vertex_cells_[static_cast<size_t>(v)].push_back(c);
    vertex_cells_valid_ = true;
  }
  return vertex_cells_;
}

const std::vector<int>& LinkedVolume::cell_components() const {
  if (components_valid_) return components_;
  components_.assign(static_cast<size_t>(cell_count()), -1);
  component_count_ = 0;
  std::vector<CellId> stack;
  for (CellId seed = 0; seed < cell_count(); ++seed) {
    if (components_[static_cast<size_t>(seed)] >= 0) continue;
    const int id = component_count_++;
    components_[static_cast<size_t>(seed)] = id;
    stack.push_back(seed);
    while (!stack.empty()) {
      const CellId c = stack.back();
      stack.pop_back();
      for (Face f = 0; f < kFaceCount; ++f) {
        if (!linked(c, f)) continue;
        const CellId n = neighbor(c, f);
        if (components_[static_cast<size_t>(n)] >= 0) continue;
        components_[static_cast<size_t>(n)] = id;
        stack.push_back(n);
      }
    }
  }
  components_valid_ = true;
  return components_;
}

int LinkedVolume::component_count() const {
  cell_components();
  return component_count_;
}

std::size_t LinkedVolume::bytes() const {
  return voxel_to_cell_.capacity() * sizeof(CellId) + voxel_.capacity() * sizeof(Vec3i) +
         label_.capacity() * sizeof(Label) + neighbor_.capacity() * sizeof(std::array<CellId, 6>) +
         cut_mask_.capacity() + corner_vertex_.capacity() * sizeof(std::array<VertexId, 8>) +
         vertex_corner_.capacity() * sizeof(Vec3i);
}

}  // namespace cleave
