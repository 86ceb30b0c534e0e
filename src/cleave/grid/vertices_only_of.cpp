#include "cleave/grid/vertices_only_of.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "cleave/core/error.hpp"

namespace cleave {

std::vector<VertexId> vertices_only_of(const LinkedVolume& volume, std::span<const CellId> cells) {
  std::vector<std::uint8_t> in_set(static_cast<std::size_t>(volume.cell_count()), 0);
  for (const CellId c : cells) {
    if (c < 0 || c >= volume.cell_count())
      throw InputError(fmt::format("cell {} is not in the volume; expected 0 to {}", c, volume.cell_count() - 1));
    in_set[static_cast<std::size_t>(c)] = 1;
  }
  std::vector<std::uint8_t> used_elsewhere(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (CellId c = 0; c < volume.cell_count(); ++c)
    if (in_set[static_cast<std::size_t>(c)] == 0)
      for (const VertexId v : volume.cell_vertices(c)) used_elsewhere[static_cast<std::size_t>(v)] = 1;
  std::vector<VertexId> out;
  for (const CellId c : cells)
    for (const VertexId v : volume.cell_vertices(c))
      if (used_elsewhere[static_cast<std::size_t>(v)] == 0) out.push_back(v);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace cleave
