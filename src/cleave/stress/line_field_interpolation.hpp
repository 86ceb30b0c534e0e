#pragma once
// Laplacian interpolation of a line field over the cells (paper eqs. 7 to 9 applied to
// eigenvectors, issue 4 item 2): the unknown per cell is the symmetric tensor X (6 Voigt
// components, each interpolated independently), found by
//   min  w_L |L X|^2 + w_C sum over targets |X(cell) - target|^2
// and X = 0 on body pieces (connected through uncut links) without any target.
// Because a target is d d^T, the result is the same for d and -d: no cancellation between
// strokes drawn in opposite directions.
//
//   LineFieldInterpolator interp(volume, weights);          // L^T L once per topology
//   std::vector<Mat3> x = interp.interpolate(targets);      // numeric factorization + 6 solves
//   x = interp.interpolate(edited_targets);                 // no factorization: CG preconditioned
//                                                           // by the kept factor, from the last x
// After an edit the kept factor (of the first system) preconditions CG on the new system; only
// when CG is off track or dearer than a new factor (at most kMaxReuseIterations) is the new
// system factorized. Never returns a non-finite tensor: ComputeError "line field interpolation:
// ..." instead (a non-finite target reaches here only through this internal API).
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/stress/sparse_cholesky.hpp"
#include "cleave/stress/stress_design.hpp"
#include "cleave/stress/stroke_constraints.hpp"

namespace cleave {

class LineFieldInterpolator {
 public:
  LineFieldInterpolator(const LinkedVolume& volume, const DesignWeights& weights);
  /// One interpolated tensor per cell. Targets must name cells of the volume (InputError otherwise).
  std::vector<Mat3> interpolate(const std::vector<LineTarget>& targets);
  static constexpr double kReuseTolerance = 1e-13;  ///< of the solve with the kept factor (SparseCholesky::solve_with_current_factor)
  static constexpr int kMaxReuseIterations = 40;
  /// Numeric factorizations done so far (1 after the first call when edits reuse the factor).
  int factorizations() const { return factorizations_; }

 private:
  const LinkedVolume& volume_;
  Eigen::SparseMatrix<double> smoothness_;  ///< w_L L^T L, ColMajor
  DesignWeights weights_;
  CellId cell_count_ = 0;
  SparseCholesky cholesky_;
  Eigen::MatrixXd previous_;  ///< last solution (n_c x 6), CG start after an edit
  int factorizations_ = 0;
};

}  // namespace cleave
