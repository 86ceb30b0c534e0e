#pragma once
// Dirichlet conditions on vertex dofs (dof 3 * vertex + axis) and their elimination from a
// linear system in the form the solvers expect (solve/linear_solver.hpp): a fixed dof's row
// and column are zero except 1 on the diagonal, and its right-hand side holds the prescribed
// value; the free rows are corrected by the prescribed values, so the matrix stays symmetric.
#include <cstdint>
#include <span>
#include <vector>

#include "cleave/core/types.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

struct FixedDofs {
  std::vector<std::uint8_t> fixed;  ///< per dof: 1 = held
  Vector value_mm;                  ///< per dof: prescribed displacement (0 where free)

  Eigen::Index dof_count() const { return value_mm.size(); }
  bool any() const;
};

/// Holds `vertices` at `displacement_mm` (one per vertex, or empty for zero displacement).
/// Throws InputError for a vertex id outside [0, vertex_count) or mismatched sizes.
FixedDofs fix_vertices(VertexId vertex_count, std::span<const VertexId> vertices,
                       std::span<const Vec3> displacement_mm = {});

/// Vertices whose reference position lies inside the axis-aligned box [lo, hi] (mm, inclusive).
std::vector<VertexId> vertices_in_box(const LinkedVolume& volume, const Vec3& lo_mm, const Vec3& hi_mm);

/// Eliminates the fixed dofs from A x = b in place (A keeps its pattern; entries become 0).
/// A must be compressed with a structurally symmetric pattern (as every vertex-block matrix is);
/// the work is proportional to the entries of the fixed rows.
void eliminate_fixed_dofs(SparseMatrix& a, Vector& b, const FixedDofs& fixed);
/// The same on a block CSR matrix (3x3 vertex blocks, structurally symmetric block pattern with
/// every diagonal block present): equal, entry by entry, to the CSR elimination of the same matrix.
void eliminate_fixed_dofs(BlockSparseMatrix<double>& a, Vector& b, const FixedDofs& fixed);

}  // namespace cleave
