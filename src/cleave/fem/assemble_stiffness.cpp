#include "cleave/fem/assemble_stiffness.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/fem/vertex_block_matrix.hpp"

namespace cleave {
namespace {

void gather_rows(const TissueModel& model, const ElementTable& table, const std::vector<std::uint8_t>* only,
                 SparseMatrix& k) {
  const LinkedVolume& volume = model.volume;
  volume.vertex_cells();
  const auto block = [&](CellId c, int a, int b) -> Mat3 {
    return table.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b);
  };
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, volume.vertex_count()), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v != r.end(); ++v)
      if (only == nullptr || (*only)[static_cast<std::size_t>(v)] != 0) gather_vertex_rows(volume, v, block, k);
  });
}

}  // namespace

SparseMatrix assemble_stiffness(const TissueModel& model, const ElementTable& table) {
  SparseMatrix k = make_vertex_block_pattern(model.volume);
  gather_rows(model, table, nullptr, k);
  return k;
}

SparseMatrix assemble_stiffness(const TissueModel& model) { return assemble_stiffness(model, make_element_table(model)); }

void update_stiffness_after_cut(const TissueModel& model, const CutReport& report, SparseMatrix& stiffness) {
  const std::vector<std::uint8_t> affected = vertices_affected_by_cut(model.volume, report);
  SparseMatrix updated = rebuild_vertex_block_pattern(model.volume, stiffness, affected);
  gather_rows(model, make_element_table(model), &affected, updated);
  stiffness.swap(updated);  // Eigen 3.4's SparseMatrix has no move assignment: std::move would copy
}

}  // namespace cleave
