#pragma once
// Multi-threaded products with a RowMajor (CSR) sparse matrix: rows are split into chunks that
// TBB runs in parallel; each row is one streaming pass over its values and column indices.
//
//   multiply(a, x, y);          // y = A x
//   residual(a, b, x, r);       // r = b - A x
//
// Inputs: a (n x m, compressed), x (m); outputs are resized to n. x and y must not alias.
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// y = A x.
void multiply(const SparseMatrix& a, const Vector& x, Vector& y);

/// r = b - A x.
void residual(const SparseMatrix& a, const Vector& b, const Vector& x, Vector& r);

}  // namespace cleave
