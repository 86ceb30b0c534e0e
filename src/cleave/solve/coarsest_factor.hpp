#pragma once
// The direct solve on the multigrid's coarsest level: a sparse Cholesky factor (CHOLMOD
// supernodal LL^T, AMD ordering), with an LDL^T of a slightly shifted matrix where the level is
// not positive definite (a free piece's rigid motions on a coarse level).
//
//   CoarsestFactor f;
//   const FactorCost cost = f.analyze(a);  // symbolic: the factor's nonzeros and flops, before any numbers
//   f.factorize(a);                       // numeric, with that analysis (analyze first if needed)
//   Eigen::VectorXd x = f.solve(b);
//
// The analysis is what lets the hierarchy choose its coarsest level by the factor's cost (its
// nonzeros: the bytes a solve streams) rather than by its dofs: a shell's level of 4,700 dofs
// factors into 170,000 entries, a solid tube's of 7,300 into 930,000.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace cleave {

/// What a factorization will cost, from the symbolic analysis.
struct FactorCost {
  double nonzeros = 0;  ///< entries of the Cholesky factor
  double flops = 0;     ///< floating-point operations of the numeric factorization
};

class CoarsestFactor {
 public:
  CoarsestFactor();
  ~CoarsestFactor();
  CoarsestFactor(const CoarsestFactor&) = delete;
  CoarsestFactor& operator=(const CoarsestFactor&) = delete;

  /// Orders `a` (symmetric, both triangles stored) and returns what its Cholesky factor will
  /// cost. The analysis is kept for factorize.
  FactorCost analyze(const Eigen::SparseMatrix<double>& a);
  /// Factors `a` (the analyzed pattern; analyzes first when analyze was not called). Where `a` is
  /// not positive definite, an LDL^T of a + 1e-10 mean|diag| I; ComputeError naming the level's
  /// size when that fails too.
  void factorize(const Eigen::SparseMatrix<double>& a);
  /// a^-1 b with the factor. InputError when b's size is not the factor's order.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

  /// Whether the factor is the LDL^T fallback (the level was not positive definite).
  bool shifted() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Index order_ = 0;
};

}  // namespace cleave
