#pragma once
// What a user designs (paper section 4): Langer-direction strokes and eigenvalue control points,
// plus the weights of the least-squares interpolation (eqs. 7 to 9) and the finishing steps.
// Plain data; parsed from the case section "design" (io/case_design.hpp) or built by the studio.
//
// Units: positions in mm (model coordinates), eigenvalues in kPa, weights dimensionless.
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// Where a stroke lies: on the body surface (its points are snapped onto the surface) or inside
/// the body (its points are used as given and must lie in a cell; the paper's future work).
enum class StrokePlacement { surface, interior };

/// A polyline along Langer's lines. Its direction of drawing does not matter (line field).
struct DesignStroke {
  std::vector<Vec3> points_mm;  ///< at least 2 points
  StrokePlacement placement = StrokePlacement::surface;
};

/// The same strokes, compared exactly (placement and every point), in the same order.
bool same_strokes(const std::vector<DesignStroke>& a, const std::vector<DesignStroke>& b);

/// Eigenvalues prescribed at a surface point (paper fig. 4); the normal eigenvalue there is 0.
struct DesignControlPoint {
  Vec3 position_mm = Vec3::Zero();
  double langer_kPa = 20.0;  ///< paper section 7: typical tension along Langer's lines
  double cross_kPa = 10.0;   ///< and across them
};

/// Weights of the least-squares terms (eq. 9). The equilibrium rows are T sigma / h^2 (kPa), so
/// all three terms compare stresses and the weights need no rescaling with the cell size.
/// Default w_E = 0: the design interpolates the control points as the user set them and the
/// exact equilibration (default on) balances it. The eq. 6 penalty (w_E > 0, the paper's form)
/// is kept: on a thin curved shell it pulls the eigenvalues to ~0 away from the control points
/// (the only field it can balance everywhere), and it makes the eigenvalue system depend on the
/// frames, so every stroke edit changes it (docs/stress-design.md).
struct DesignWeights {
  double laplacian = 1.0;      ///< smoothness, L lambda = 0 (eq. 7)
  double constraint = 1000.0;  ///< strokes and control points, C lambda = lambda0 (eq. 8)
  double equilibrium = 0.0;    ///< T (d sigma / d lambda) lambda = 0 (eq. 6); 0 = off (default)
};

/// How the eigenvalue normal equations A^T A lambda = A^T b are solved.
enum class EigenvalueSolver {
  cholesky,  ///< default: sparse Cholesky (CHOLMOD supernodal) of A^T A, kept to precondition CG after edits
  paper_cg,  ///< reference: the paper's plain conjugate gradients on A^T A, one thread
};

/// Where the equilibrium equations hold (paper eqs. 1, 2: sigma n = 0 only on the free surface
/// Gamma_N). The held vertices (Gamma_D, e.g. the rim of the demo's abdominal wall) may carry
/// reactions, so the eq. 6 rows and the exact equilibration skip them. Default `simulation`:
/// the design is balanced on the body the simulation deforms; a case that holds nothing is a
/// free body, where both choices are the same (every vertex balanced, mean stress 0).
enum class EquilibriumSupport {
  none,        ///< free body: equilibrium at every vertex (Hoger: mean stress 0)
  simulation,  ///< default: the vertices that the case's "simulation" section holds (stage_residual_stress)
};

/// Whether the designed field is made exactly self-balanced afterwards (equilibrate_stress.hpp).
enum class Equilibration {
  none,    ///< keep the least-squares design as it is
  growth,  ///< remove the compatible part of the design's eigenstrain (one elastic solve)
};

struct StressDesign {
  std::vector<DesignStroke> strokes;
  std::vector<DesignControlPoint> control_points;
  DesignWeights weights;
  EigenvalueSolver solver = EigenvalueSolver::cholesky;
  Equilibration equilibration = Equilibration::growth;
  EquilibriumSupport support = EquilibriumSupport::simulation;
  /// Held vertices (uncut model's vertex ids) where equilibrium is not imposed; empty = free body.
  /// Filled from the simulation section when support == simulation; may be set directly.
  std::vector<VertexId> held_vertices;
  /// Surface points farther than this many cell sizes from the body surface are refused.
  double snap_tolerance_cells = 2.0;
};

}  // namespace cleave
