#pragma once
// Topology of a triangle surface: is it closed and consistently oriented, how many pieces, which
// genus. Used by the tests and by the run summary (closed components of the render surface).
#include <array>
#include <cstdint>
#include <vector>

namespace cleave {

struct SurfaceTopology {
  std::int64_t vertices = 0;   ///< vertices used by at least one triangle
  std::int64_t edges = 0;      ///< undirected edges
  std::int64_t triangles = 0;
  std::int64_t open_edges = 0;         ///< undirected edges used by one triangle only
  std::int64_t non_manifold_edges = 0; ///< undirected edges used by more than two triangles
  std::int64_t misoriented_edges = 0;  ///< directed edges used more than once (inconsistent orientation)
  int components = 0;                  ///< connected pieces (through shared vertices)
  std::int64_t euler_characteristic() const { return vertices - edges + triangles; }
  /// Every edge used by exactly two triangles, once in each direction.
  bool closed_and_oriented() const { return open_edges == 0 && non_manifold_edges == 0 && misoriented_edges == 0; }
};

/// Counts of `triangles` (vertex indices below `vertex_count`). Cost O(T log T).
SurfaceTopology surface_topology(const std::vector<std::array<std::int32_t, 3>>& triangles, std::int32_t vertex_count);

}  // namespace cleave
