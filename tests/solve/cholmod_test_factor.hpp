#pragma once
// CHOLMOD's supernodal LL^T of a test matrix, the factor the substitution tests work on, and
// cholmod_solve as their reference.
#include <cholmod.h>
#include <gtest/gtest.h>

#include <Eigen/Core>

#include "cleave/solve/linear_solver.hpp"

namespace cleave::test {

/// CHOLMOD's supernodal LL^T of a symmetric matrix stored whole (its upper triangle is read).
class CholmodFactor {
 public:
  explicit CholmodFactor(SparseMatrix& a) : a_(a) {
    cholmod_start(&common_);
    common_.supernodal = CHOLMOD_SUPERNODAL;
    common_.print = 0;
    factor_ = cholmod_analyze(view(), &common_);
    refactor();
  }
  ~CholmodFactor() {
    cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;

  /// Numeric factorization of a_'s current values (same analysis).
  void refactor() {
    cholmod_factorize(view(), factor_, &common_);
    ASSERT_EQ(factor_->minor, factor_->n) << "test matrix not positive definite";
  }
  const cholmod_factor& factor() const { return *factor_; }

  /// x = A^-1 b by cholmod_solve: the reference.
  Eigen::MatrixXd cholmod_solution(const Eigen::MatrixXd& b) {
    cholmod_dense rhs{};
    rhs.nrow = static_cast<std::size_t>(b.rows());
    rhs.ncol = static_cast<std::size_t>(b.cols());
    rhs.nzmax = rhs.nrow * rhs.ncol;
    rhs.d = rhs.nrow;
    rhs.x = const_cast<double*>(b.data());
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common_);
    Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), b.rows(), b.cols());
    cholmod_free_dense(&x, &common_);
    return out;
  }

 private:
  cholmod_sparse* view() {
    view_.nrow = view_.ncol = static_cast<std::size_t>(a_.rows());
    view_.nzmax = static_cast<std::size_t>(a_.nonZeros());
    view_.p = a_.outerIndexPtr();
    view_.i = a_.innerIndexPtr();
    view_.x = a_.valuePtr();
    view_.stype = 1;
    view_.itype = CHOLMOD_INT;
    view_.xtype = CHOLMOD_REAL;
    view_.dtype = CHOLMOD_DOUBLE;
    view_.sorted = 1;
    view_.packed = 1;
    return &view_;
  }
  SparseMatrix& a_;
  cholmod_common common_{};
  cholmod_sparse view_{};
  cholmod_factor* factor_ = nullptr;
};

}  // namespace cleave::test
