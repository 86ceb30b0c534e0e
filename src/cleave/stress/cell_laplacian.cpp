#include "cleave/stress/cell_laplacian.hpp"

#include <vector>

namespace cleave {

SparseMatrix cell_laplacian(const LinkedVolume& volume) {
  const CellId n = volume.cell_count();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(n) * 7);
  for (CellId c = 0; c < n; ++c) {
    int linked = 0;
    for (Face f = 0; f < kFaceCount; ++f) linked += volume.linked(c, f) ? 1 : 0;
    entries.emplace_back(c, c, -1.0);
    if (linked == 0) continue;
    const double w = 1.0 / linked;
    for (Face f = 0; f < kFaceCount; ++f)
      if (volume.linked(c, f)) entries.emplace_back(c, volume.neighbor(c, f), w);
  }
  SparseMatrix l(n, n);
  l.setFromTriplets(entries.begin(), entries.end());
  return l;
}

std::vector<bool> cells_of_unconstrained_pieces(const LinkedVolume& volume, const std::vector<CellId>& constrained_cells) {
  const std::vector<int>& component = volume.cell_components();
  std::vector<bool> piece_constrained(static_cast<std::size_t>(volume.component_count()), false);
  for (CellId c : constrained_cells)
    if (c >= 0 && c < volume.cell_count()) piece_constrained[static_cast<std::size_t>(component[static_cast<std::size_t>(c)])] = true;
  std::vector<bool> out(static_cast<std::size_t>(volume.cell_count()));
  for (std::size_t c = 0; c < out.size(); ++c) out[c] = !piece_constrained[static_cast<std::size_t>(component[c])];
  return out;
}

}  // namespace cleave
