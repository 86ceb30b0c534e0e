#include "cleave/surface/surface_topology.hpp"

#include <algorithm>
#include <numeric>

namespace cleave {

SurfaceTopology surface_topology(const std::vector<std::array<std::int32_t, 3>>& triangles, std::int32_t vertex_count) {
  SurfaceTopology t;
  t.triangles = static_cast<std::int64_t>(triangles.size());
  std::vector<std::int64_t> directed;
  directed.reserve(3 * triangles.size());
  std::vector<std::int32_t> parent(static_cast<size_t>(vertex_count));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](std::int32_t v) {
    while (parent[static_cast<size_t>(v)] != v) v = parent[static_cast<size_t>(v)] = parent[static_cast<size_t>(parent[static_cast<size_t>(v)])];
    return v;
  };
  std::vector<bool> used(static_cast<size_t>(vertex_count), false);
  for (const auto& tri : triangles)
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = tri[static_cast<size_t>(i)];
      const std::int32_t b = tri[static_cast<size_t>((i + 1) % 3)];
      directed.push_back(std::int64_t{a} * vertex_count + b);
      used[static_cast<size_t>(a)] = true;
      const std::int32_t ra = find(a);
      const std::int32_t rb = find(b);
      if (ra != rb) parent[static_cast<size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  for (std::int32_t v = 0; v < vertex_count; ++v) {
    if (!used[static_cast<size_t>(v)]) continue;
    ++t.vertices;
    if (find(v) == v) ++t.components;
  }
  std::sort(directed.begin(), directed.end());
  std::vector<std::int64_t> undirected;
  undirected.reserve(directed.size());
  for (size_t i = 0; i < directed.size(); ++i) {
    if (i > 0 && directed[i] == directed[i - 1]) ++t.misoriented_edges;
    const std::int64_t a = directed[i] / vertex_count;
    const std::int64_t b = directed[i] % vertex_count;
    undirected.push_back(std::min(a, b) * vertex_count + std::max(a, b));
  }
  std::sort(undirected.begin(), undirected.end());
  for (size_t i = 0; i < undirected.size();) {
    size_t j = i;
    while (j < undirected.size() && undirected[j] == undirected[i]) ++j;
    ++t.edges;
    if (j - i == 1) ++t.open_edges;
    if (j - i > 2) ++t.non_manifold_edges;
    i = j;
  }
  return t;
}

}  // namespace cleave
