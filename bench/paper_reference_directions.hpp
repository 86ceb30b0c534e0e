#pragma once
// The paper's own eigenvector interpolation (section 6.3), re-run as a peer: the Langer line
// field and the normal line field are each interpolated component-wise (6 Voigt components of
// the line tensor d d^T) by the least squares of eqs. 7 to 9, solved on the normal equations
//   (w_L L^T L + w_C C^T C + 1e-10 w_L I) x = w_C C^T x0
// with plain, unpreconditioned conjugate gradients on one thread (the paper: "evaluated by a
// conjugate gradient solver"), then orthonormalized into frames (stress/direction_frames.hpp).
// It uses the same operators and targets as cleave's StressDesigner (cell_laplacian,
// stroke_line_targets, surface_normal_targets), so both solve the same system and their frames
// must agree; only the solver differs (cleave: sparse Cholesky with the normals cached).
//
//   PaperDirections paper(model, design);          // L^T L once
//   PaperDirectionResult r = paper.interpolate(design.strokes);   // warm-started from the last call
#include <Eigen/SparseCore>
#include <vector>

#include "cleave/model/tissue_model.hpp"
#include "cleave/stress/direction_frames.hpp"
#include "cleave/stress/stress_design.hpp"

namespace cleave::bench {

/// Relative residual at which the paper's CG stops (the stress engineer's paper CG uses 1e-12
/// for eigenvalues; the line fields are smoother and need no more than this for 1e-6 agreement).
inline constexpr double kPaperCgRelativeTolerance = 1e-10;
inline constexpr int kPaperCgMaxIterations = 100'000;

struct PaperDirectionResult {
  std::vector<DirectionFrame> frames;  ///< per cell
  int iterations = 0;                  ///< CG iterations, summed over the 12 component solves
};

class PaperDirections {
 public:
  PaperDirections(const TissueModel& model, const StressDesign& design);
  /// Interpolates the Langer field of `strokes` and the normal field. ComputeError when CG does
  /// not reach the tolerance.
  PaperDirectionResult interpolate(const std::vector<DesignStroke>& strokes);

 private:
  const TissueModel& model_;
  StressDesign design_;
  Eigen::SparseMatrix<double, Eigen::RowMajor> smoothness_;
  Eigen::MatrixXd langer_guess_, normal_guess_;  ///< last solutions (warm start), n_c x 6
};

/// Per cell the line tensors l l^T and n n^T of the frames, flattened (for relative differences
/// that do not depend on the sign of the eigenvectors).
Eigen::VectorXd frame_line_tensors(const std::vector<DirectionFrame>& frames);

}  // namespace cleave::bench
