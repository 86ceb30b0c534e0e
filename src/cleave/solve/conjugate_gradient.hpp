#pragma once
// Preconditioned conjugate gradients on a symmetric positive definite sparse matrix, with a
// preconditioner behind a small interface so that block Jacobi and the multigrid V-cycle plug in.
//
//   SolveReport r = preconditioned_cg(a, b, x, preconditioner, settings);
//
// Inputs:  a  n x n SPD, compressed RowMajor (fixed dofs as identity rows, see linear_solver.hpp)
//          b  n right-hand side;  x  n initial guess (warm start), overwritten by the solution
//          preconditioner  z = M^-1 r with M symmetric positive definite
// Output:  iterations done, relative residual ||b - A x|| / ||b|| reached (the true residual,
//          recomputed at the end), converged when it is <= settings.relative_tolerance or, with
//          settings.initial_residual_tolerance > 0, when ||b - A x|| <= that * ||b - A x0||.
// With settings.zero_start_when_better, x = 0 replaces an initial guess that is farther from the
// solution in the energy norm. Edge cases: b = 0 gives x = 0 and converged after 0 iterations. A
// non-finite x on entry is replaced by 0. When the iteration breaks down (non-positive
// curvature, NaN) or runs out of iterations, x keeps its last finite value (at worst the initial
// guess) and converged = false: x never holds NaN. Restarts from the true residual when rounding
// drift fools the recurrence.
// With settings.single_precision_products (operators only) each iteration's q = A p is a float
// product; the initial and the final (true) residual stay in double, so the report never rests
// on the float products.
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/solve/vertex_operator.hpp"

namespace cleave {

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  /// z = M^-1 r (z is resized to r's size).
  virtual void apply(const Vector& r, Vector& z) const = 0;
};

/// M = identity.
class IdentityPreconditioner final : public Preconditioner {
 public:
  void apply(const Vector& r, Vector& z) const override { z = r; }
};

SolveReport preconditioned_cg(const SparseMatrix& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings);
/// The same on a block CSR matrix (fewer bytes per product; block_sparse_matrix.hpp).
SolveReport preconditioned_cg(const BlockSparseMatrix<double>& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings);
/// The same with A applied without its matrix (solve/vertex_operator.hpp).
SolveReport preconditioned_cg(const VertexOperator& a, const Vector& b, Vector& x, const Preconditioner& preconditioner,
                              const SolveSettings& settings);

}  // namespace cleave
