#include "cleave/solve/coarsen_grid_level.hpp"

#include <algorithm>
#include <numeric>

namespace cleave {
namespace {

/// Union-find with path halving over 0..n-1.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::size_t> parent_;
};

Vec3i parent_voxel(const Vec3i& v) { return {v.x() / 2, v.y() / 2, v.z() / 2}; }

std::int64_t linear_index(const Vec3i& v, const Vec3i& dims) {
  return (std::int64_t{v.z()} * dims.y() + v.y()) * dims.x() + v.x();
}

/// Coarse cells: one per connected group of fine cells inside each 2x2x2 block, numbered in
/// block order (then by the group's smallest fine cell), so the result is deterministic.
void make_coarse_cells(const GridLevel& fine, Coarsening& out) {
  const auto cells = static_cast<std::size_t>(fine.cell_count());
  const Vec3i coarse_dims = (fine.dims + Vec3i::Ones()) / 2;
  std::vector<std::int64_t> block(cells);
  for (std::size_t c = 0; c < cells; ++c) block[c] = linear_index(parent_voxel(fine.cell_voxel[c]), coarse_dims);
  DisjointSets groups(cells);
  for (const LevelLink& link : fine.links) {
    const auto a = static_cast<std::size_t>(link.from), b = static_cast<std::size_t>(link.to);
    if (block[a] == block[b]) groups.unite(a, b);
  }
  std::vector<std::size_t> order(cells);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::size_t> root(cells);
  for (std::size_t c = 0; c < cells; ++c) root[c] = groups.find(c);  // roots are the smallest member
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return block[a] != block[b] ? block[a] < block[b] : root[a] < root[b];
  });
  out.coarse_cell_of_fine.assign(cells, kNone);
  out.coarse.dims = coarse_dims;
  for (std::size_t k = 0; k < cells; ++k) {
    const std::size_t c = order[k];
    if (root[c] != c) continue;  // not the group's first cell
    out.coarse_cell_of_fine[c] = static_cast<CellId>(out.coarse.cell_voxel.size());
    out.coarse.cell_voxel.push_back(parent_voxel(fine.cell_voxel[c]));
  }
  for (std::size_t c = 0; c < cells; ++c) out.coarse_cell_of_fine[c] = out.coarse_cell_of_fine[root[c]];
}

/// Coarse links from fine links that cross a block face; duplicates removed.
void make_coarse_links(const GridLevel& fine, Coarsening& out) {
  auto& links = out.coarse.links;
  for (const LevelLink& link : fine.links) {
    const CellId a = out.coarse_cell_of_fine[static_cast<std::size_t>(link.from)];
    const CellId b = out.coarse_cell_of_fine[static_cast<std::size_t>(link.to)];
    if (a != b) links.push_back({a, b, link.face});
  }
  std::sort(links.begin(), links.end(), [](const LevelLink& x, const LevelLink& y) {
    return x.from != y.from ? x.from < y.from : x.to != y.to ? x.to < y.to : x.face < y.face;
  });
  links.erase(std::unique(links.begin(), links.end(),
                          [](const LevelLink& x, const LevelLink& y) { return x.from == y.from && x.to == y.to && x.face == y.face; }),
              links.end());
}

/// Coarse vertices: classes of (cell, corner) slots joined across every coarse link's face.
void make_coarse_vertices(Coarsening& out) {
  GridLevel& coarse = out.coarse;
  const auto cells = static_cast<std::size_t>(coarse.cell_count());
  DisjointSets slots(cells * kCornerCount);
  for (const LevelLink& link : coarse.links) {
    const int axis_bit = 1 << (link.face / 2);
    for (const int corner : face_corners(link.face))
      slots.unite(static_cast<std::size_t>(link.from) * kCornerCount + static_cast<std::size_t>(corner),
                  static_cast<std::size_t>(link.to) * kCornerCount + static_cast<std::size_t>(corner ^ axis_bit));
  }
  std::vector<VertexId> vertex_of_root(cells * kCornerCount, kNone);
  coarse.cell_vertices.resize(cells);
  VertexId next = 0;
  for (std::size_t s = 0; s < cells * kCornerCount; ++s) {
    const std::size_t r = slots.find(s);
    if (vertex_of_root[r] == kNone) vertex_of_root[r] = next++;
    coarse.cell_vertices[s / kCornerCount][s % kCornerCount] = vertex_of_root[r];
  }
  coarse.vertex_count = next;
}

/// Trilinear weights of each fine vertex inside the coarse cell of the first fine cell using it.
void make_prolongation(const GridLevel& fine, Coarsening& out) {
  const auto fine_vertices = static_cast<std::size_t>(fine.vertex_count);
  std::vector<CellId> host(fine_vertices, kNone);
  std::vector<int> host_corner(fine_vertices, 0);
  for (CellId c = 0; c < fine.cell_count(); ++c)
    for (int k = 0; k < kCornerCount; ++k) {
      const auto v = static_cast<std::size_t>(fine.cell_vertices[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)]);
      if (host[v] == kNone) {
        host[v] = c;
        host_corner[v] = k;
      }
    }
  Prolongation& p = out.prolongation;
  p.fine_start.assign(fine_vertices + 1, 0);
  p.by_fine.clear();
  for (std::size_t v = 0; v < fine_vertices; ++v) {
    p.fine_start[v] = static_cast<int>(p.by_fine.size());
    const CellId c = host[v];
    if (c == kNone) continue;  // a vertex of no cell has no coarse value
    const auto cell = static_cast<std::size_t>(c);
    const CellId coarse_cell = out.coarse_cell_of_fine[cell];
    const Vec3i corner = fine.cell_voxel[cell] + corner_offset(host_corner[v]);
    // Position inside the coarse cell in half-cells: 0, 1 or 2 per axis.
    const Vec3i half = corner - 2 * out.coarse.cell_voxel[static_cast<std::size_t>(coarse_cell)];
    for (int k = 0; k < kCornerCount; ++k) {
      const Vec3i bit = corner_offset(k);
      double weight = 1;
      for (int axis = 0; axis < 3; ++axis) weight *= 0.5 * (bit[axis] == 1 ? half[axis] : 2 - half[axis]);
      if (weight > 0)
        p.by_fine.push_back({out.coarse.cell_vertices[static_cast<std::size_t>(coarse_cell)][static_cast<std::size_t>(k)], weight});
    }
  }
  p.fine_start[fine_vertices] = static_cast<int>(p.by_fine.size());

  const auto coarse_vertices = static_cast<std::size_t>(out.coarse.vertex_count);
  p.coarse_start.assign(coarse_vertices + 1, 0);
  for (const auto& e : p.by_fine) ++p.coarse_start[static_cast<std::size_t>(e.vertex) + 1];
  std::partial_sum(p.coarse_start.begin(), p.coarse_start.end(), p.coarse_start.begin());
  p.by_coarse.resize(p.by_fine.size());
  std::vector<int> fill(p.coarse_start.begin(), p.coarse_start.end() - 1);
  for (std::size_t v = 0; v < fine_vertices; ++v)
    for (int k = p.fine_start[v]; k < p.fine_start[v + 1]; ++k) {
      const auto& e = p.by_fine[static_cast<std::size_t>(k)];
      p.by_coarse[static_cast<std::size_t>(fill[static_cast<std::size_t>(e.vertex)]++)] = {static_cast<VertexId>(v), e.weight};
    }
}

}  // namespace

Coarsening coarsen_grid_level(const GridLevel& fine) {
  Coarsening out;
  make_coarse_cells(fine, out);
  make_coarse_links(fine, out);
  make_coarse_vertices(out);
  make_prolongation(fine, out);
  return out;
}

}  // namespace cleave
