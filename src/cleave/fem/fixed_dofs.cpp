#include "cleave/fem/fixed_dofs.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {

bool FixedDofs::any() const { return std::any_of(fixed.begin(), fixed.end(), [](std::uint8_t f) { return f != 0; }); }

FixedDofs fix_vertices(VertexId vertex_count, std::span<const VertexId> vertices, std::span<const Vec3> displacement_mm) {
  if (!displacement_mm.empty() && displacement_mm.size() != vertices.size())
    throw InputError(fmt::format("{} prescribed displacements for {} fixed vertices; expected one per vertex or none",
                                 displacement_mm.size(), vertices.size()));
  FixedDofs out;
  const auto dofs = 3 * static_cast<Eigen::Index>(vertex_count);
  out.fixed.assign(static_cast<std::size_t>(dofs), 0);
  out.value_mm = Vector::Zero(dofs);
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const VertexId v = vertices[k];
    if (v < 0 || v >= vertex_count)
      throw InputError(fmt::format("fixed vertex {} does not exist; expected an id from 0 to {}", v, vertex_count - 1));
    for (int i = 0; i < 3; ++i) {
      out.fixed[static_cast<std::size_t>(3 * v + i)] = 1;
      out.value_mm[3 * v + i] = displacement_mm.empty() ? 0.0 : displacement_mm[k][i];
    }
  }
  return out;
}

std::vector<VertexId> vertices_in_box(const LinkedVolume& volume, const Vec3& lo_mm, const Vec3& hi_mm) {
  std::vector<VertexId> out;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 p = volume.vertex_position_mm(v);
    if ((p.array() >= lo_mm.array()).all() && (p.array() <= hi_mm.array()).all()) out.push_back(v);
  }
  return out;
}

void eliminate_fixed_dofs(SparseMatrix& a, Vector& b, const FixedDofs& fixed) {
  const auto* outer = a.outerIndexPtr();
  const auto* inner = a.innerIndexPtr();
  double* values = a.valuePtr();
  const auto is_fixed = [&](Eigen::Index dof) { return fixed.fixed[static_cast<std::size_t>(dof)] != 0; };
  // Work only around the fixed dofs: entry (i, j) with j fixed is found from row j through the
  // symmetric pattern, so the cost is proportional to the fixed rows, not to the matrix.
  for (Eigen::Index j = 0; j < a.rows(); ++j) {
    if (!is_fixed(j)) continue;
    const double prescribed = fixed.value_mm[j];
    for (auto k = outer[j]; k < outer[j + 1]; ++k) {
      const Eigen::Index i = inner[k];
      if (i == j || is_fixed(i)) continue;
      const auto* row_begin = inner + outer[i];
      const auto* row_end = inner + outer[i + 1];
      const auto* found = std::lower_bound(row_begin, row_end, static_cast<SparseMatrix::StorageIndex>(j));
      if (found == row_end || *found != j) continue;  // structurally zero
      double& entry = values[found - inner];
      b[i] -= entry * prescribed;
      entry = 0.0;
    }
    for (auto k = outer[j]; k < outer[j + 1]; ++k) values[k] = inner[k] == j ? 1.0 : 0.0;
    b[j] = prescribed;
  }
}

void eliminate_fixed_dofs(BlockSparseMatrix<double>& a, Vector& b, const FixedDofs& fixed) {
  const auto is_fixed = [&](Eigen::Index dof) { return fixed.fixed[static_cast<std::size_t>(dof)] != 0; };
  const auto block_of = [&](Eigen::Index row, Eigen::Index column) -> double* {
    const auto first = a.column.begin() + a.row_start[static_cast<std::size_t>(row)];
    const auto last = a.column.begin() + a.row_start[static_cast<std::size_t>(row) + 1];
    const auto found = std::lower_bound(first, last, static_cast<std::int32_t>(column));
    if (found == last || *found != column) return nullptr;  // structurally zero
    return a.values.data() + 9 * static_cast<std::size_t>(found - a.column.begin());
  };
  for (Eigen::Index v = 0; v < a.block_rows(); ++v) {
    if (!is_fixed(3 * v) && !is_fixed(3 * v + 1) && !is_fixed(3 * v + 2)) continue;
    // Column side first (entry (i, j), j fixed, i free, found in block row w through the
    // symmetric pattern), then the fixed rows themselves.
    for (auto k = a.row_start[static_cast<std::size_t>(v)]; k < a.row_start[static_cast<std::size_t>(v) + 1]; ++k) {
      const Eigen::Index w = a.column[static_cast<std::size_t>(k)];
      double* mirror = block_of(w, v);
      if (mirror == nullptr) continue;
      for (int jj = 0; jj < 3; ++jj) {
        const Eigen::Index j = 3 * v + jj;
        if (!is_fixed(j)) continue;
        for (int ii = 0; ii < 3; ++ii) {
          const Eigen::Index i = 3 * w + ii;
          if (i == j || is_fixed(i)) continue;
          double& entry = mirror[3 * ii + jj];
          b[i] -= entry * fixed.value_mm[j];
          entry = 0.0;
        }
      }
    }
    for (auto k = a.row_start[static_cast<std::size_t>(v)]; k < a.row_start[static_cast<std::size_t>(v) + 1]; ++k) {
      const Eigen::Index w = a.column[static_cast<std::size_t>(k)];
      double* block = a.values.data() + 9 * static_cast<std::size_t>(k);
      for (int ii = 0; ii < 3; ++ii) {
        if (!is_fixed(3 * v + ii)) continue;
        for (int jj = 0; jj < 3; ++jj) block[3 * ii + jj] = (w == v && ii == jj) ? 1.0 : 0.0;
      }
    }
    for (int ii = 0; ii < 3; ++ii)
      if (is_fixed(3 * v + ii)) b[3 * v + ii] = fixed.value_mm[3 * v + ii];
  }
}

}  // namespace cleave
