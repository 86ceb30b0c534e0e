// GCC 12 reports -Wnull-dereference inside Eigen's CHOLMOD wrapper (the sparse view it makes of
// the matrix), after inlining; the pointers are those of a compressed matrix.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/solve/coarsest_factor.hpp"

#include <fmt/format.h>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

/// Diagonal shift (relative to the mean diagonal) of the LDL^T fallback.
constexpr double kShift = 1e-10;

}  // namespace

struct CoarsestFactor::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analyzed = false;
  bool shifted = false;

  Impl() {
    // One ordering (AMD) and no METIS trial: a coarse level's analysis costs 1-10 ms this way.
    cholmod_common& c = llt.cholmod();
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_AMD;
    c.print = 0;  // a matrix that is not positive definite is reported by info(), not on stdout
    c.error_handler = nullptr;
  }
};

CoarsestFactor::CoarsestFactor() : impl_(std::make_unique<Impl>()) {}
CoarsestFactor::~CoarsestFactor() = default;

FactorCost CoarsestFactor::analyze(const Eigen::SparseMatrix<double>& a) {
  impl_->llt.analyzePattern(a);
  impl_->analyzed = true;
  order_ = a.rows();
  return {impl_->llt.cholmod().lnz, impl_->llt.cholmod().fl};
}

void CoarsestFactor::factorize(const Eigen::SparseMatrix<double>& a) {
  if (!impl_->analyzed || order_ != a.rows()) analyze(a);
  impl_->shifted = false;
  impl_->llt.factorize(a);
  if (impl_->llt.info() == Eigen::Success) return;
  impl_->shifted = true;
  const double shift = kShift * a.diagonal().cwiseAbs().mean();
  Eigen::SparseMatrix<double> identity(a.rows(), a.cols());
  identity.setIdentity();
  impl_->ldlt.compute(a + shift * identity);
  if (impl_->ldlt.info() != Eigen::Success)
    throw ComputeError(fmt::format("multigrid: the coarsest level ({} dofs) cannot be factored", a.rows()));
}

Eigen::VectorXd CoarsestFactor::solve(const Eigen::VectorXd& b) const {
  if (b.size() != order_)
    throw InputError(fmt::format("coarsest factor: right-hand side has {} rows; expected {}", b.size(), order_));
  return impl_->shifted ? Eigen::VectorXd(impl_->ldlt.solve(b)) : Eigen::VectorXd(impl_->llt.solve(b));
}

bool CoarsestFactor::shifted() const { return impl_->shifted; }

}  // namespace cleave
