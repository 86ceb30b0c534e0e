// GCC 12 reports -Wnull-dereference inside Eigen (sparse Ref construction, vector dot products)
// after inlining: a false positive for possibly-empty vectors. Silenced for this file's headers.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/stress/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <cmath>
#include <vector>

#include "cleave/core/error.hpp"

namespace cleave {

struct SparseCholesky::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  std::vector<int> outer;
  std::vector<int> inner;
  bool analyzed = false;

  bool same_pattern(const Eigen::SparseMatrix<double>& a) const {
    if (!analyzed || static_cast<std::size_t>(a.outerSize() + 1) != outer.size()) return false;
    for (std::size_t i = 0; i < outer.size(); ++i)
      if (outer[i] != a.outerIndexPtr()[i]) return false;
    if (static_cast<std::size_t>(outer.back()) != inner.size()) return false;
    for (std::size_t i = 0; i < inner.size(); ++i)
      if (inner[i] != a.innerIndexPtr()[i]) return false;
    return true;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::factorize(const Eigen::SparseMatrix<double>& a) {
  if (!a.isCompressed()) throw ComputeError("sparse Cholesky needs a compressed matrix");
  if (impl_->same_pattern(a)) {
    ++reused_;
  } else {
    impl_->llt.analyzePattern(a);
    impl_->outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
    impl_->inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + impl_->outer.back());
    impl_->analyzed = true;
  }
  impl_->llt.factorize(a);
  if (impl_->llt.info() != Eigen::Success) {
    impl_->analyzed = false;
    throw ComputeError("sparse Cholesky factorization failed: the design system is not positive definite");
  }
}

Eigen::MatrixXd SparseCholesky::solve_refined(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x = solve(b);
  for (int step = 0; step < kRefinementSteps; ++step) {
    const Eigen::MatrixXd r = b - a * x;
    x += solve(r);
  }
  return x;
}

bool SparseCholesky::solve_with_current_factor(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& b,
                                               Eigen::MatrixXd& x, double relative_tolerance, int max_iterations) const {
  if (!impl_->analyzed || !impl_->same_pattern(a) || x.rows() != b.rows() || x.cols() != b.cols()) return false;
  for (Eigen::Index col = 0; col < b.cols(); ++col) {
    const double b_norm = b.col(col).norm();
    if (b_norm == 0.0) {
      x.col(col).setZero();
      continue;
    }
    Eigen::VectorXd xc = x.col(col);
    Eigen::VectorXd r = b.col(col) - a * xc;
    if (r.norm() <= relative_tolerance * b_norm) continue;
    Eigen::VectorXd z = impl_->llt.solve(r);
    Eigen::VectorXd p = z;
    double rz = r.dot(z);
    bool converged = false;
    for (int it = 0; it < max_iterations && !converged; ++it) {
      const Eigen::VectorXd ap = a * p;
      const double curvature = p.dot(ap);
      if (!(curvature > 0.0) || !(rz > 0.0)) return false;
      const double alpha = rz / curvature;
      xc += alpha * p;
      r -= alpha * ap;
      converged = r.norm() <= relative_tolerance * b_norm;
      if (converged) break;
      // Off track for a geometric rate (a stroke edit changes hundreds of rows: CG stalls near
      // 1e-5): give up early so the caller's factorization is not preceded by wasted solves.
      if (it + 1 == max_iterations / 4 && r.norm() > std::sqrt(relative_tolerance) * b_norm) return false;
      z = impl_->llt.solve(r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    if (!converged || !xc.allFinite()) return false;
    if ((b.col(col) - a * xc).norm() > 10.0 * relative_tolerance * b_norm) return false;  // recurrence drifted
    x.col(col) = xc;
  }
  return true;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x = impl_->llt.solve(b);
  if (impl_->llt.info() != Eigen::Success || !x.allFinite())
    throw ComputeError("sparse Cholesky solve failed or produced a non-finite value");
  return x;
}

}  // namespace cleave
