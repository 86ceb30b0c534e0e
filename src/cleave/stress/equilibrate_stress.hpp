#pragma once
// Makes a designed residual stress exactly self-balanced on the uncut body (issue 4, item 5),
// in the kinematic-growth view of paper section 3.2: the design sigma_d is read as the stress of
// an incompatible eigenstrain; its compatible part is removed by one elastic solve.
//
// With the one-point (cell-centre) strain matrix Bc of each cube, T^e = V Bc^T exactly (the
// trilinear B averages to its centre value). Solving
//   Kc u = -T sigma_d,   Kc = sum over cells of V Bc^T D Bc    (D of the cell's material)
// and setting sigma = sigma_d + D Bc u gives T sigma = T sigma_d + Kc u = 0.
//
// Why this needs care (issue 4): Kc is singular far beyond the rigid modes. One-point quadrature
// has exact global hourglass modes (u_x = f(i) (-1)^(j+k) and its permutations, for any f), and
// thin shells such as the abdomen (2 to 4 cells thick) have bending modes whose eigenvalues are
// ~1e-6 of the mean diagonal. The right-hand side lies in the range of Kc, and the null modes do
// not change D Bc u, but a stationary refinement with a shifted factor stalls on the soft modes
// (the old code: 4.6e-7 after 100 steps on the abdomen). Here the factor of Kc + eps I
// (eps = 1e-10 of the mean diagonal, computed once per topology) preconditions conjugate
// gradients on Kc itself: the few eigenvalues of the preconditioned operator that are not close
// to 1 (soft and near-hourglass modes) are what CG removes in a handful of iterations. The best
// iterate is kept, since rounding in the null space makes CG drift after convergence; the solve
// stops at ||T sigma|| <= 5e-11 ||T sigma_d|| (the rounding floor lies between 1e-12 and 5e-11).
// Edits: each solve starts from the last displacement, and its first step minimizes the energy
// over the factor's correction and the soft modes learned from earlier solves (what CG corrected
// after its first step, Kc-orthonormal, at most 16): an edit back to an earlier design (a drag
// back and forth, undo, redo) needs one solve with the factor instead of two to four; and a design
// equal to one of the last two (bit for bit) is answered from memory with no solve at all.
// The CG steps after the first are preconditioned with a single-precision copy of the factor
// (half the bytes, about half the time) while each gains at least 10x, then with the double one:
// an edit over fresh cells needs one such step after its first (residual 1e-10..1e-8 -> below
// 5e-11).
// Kc is applied cell by cell (stress/centre_point_stiffness.hpp: ~1 ms per product at 44k cells
// instead of ~4 ms for the assembled 140 MB matrix, and its residual of a rigid or hourglass motion
// is exactly zero); it is assembled only to be factorized, then dropped.
// Consequences: the uncut, unsupported body does not move under sigma, and the volume average of
// sigma is exactly zero (Hoger's theorem, section 3.1), since T sigma = 0 for a field on cubes
// implies sum_c V sigma_c = 0.
//
// A picture first: a stress accurate to 1e-6 of the designed forces moves the body by 1e-6 of what
// the design would, far below what the incision preview resolves (its solve stops at 1e-4). With
// EquilibrationPass::picture an edit whose first step already ends below kPictureReduction returns
// that stress as provisional (an edit over fresh cells: 1e-10..1e-8 after the first step, then one
// more step to 5e-11); finish() then takes the same steps the complete pass would have taken from
// there, bit for bit. The studio draws the picture between the two.
//
//   StressEquilibrator eq(model);                 // Kc and its factor, once per topology
//   EquilibrationResult r = eq.equilibrate(designed_kPa);   // per edit, warm-started
//   r.stress_kPa  // per cell, Voigt
//   EquilibrationResult p = eq.equilibrate(designed_kPa, EquilibrationPass::picture);
//   if (p.provisional) { draw(p.stress_kPa); p = eq.finish(); }
#include <memory>
#include <span>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

struct EquilibrationResult {
  std::vector<Vec6> stress_kPa;         ///< self-balanced field, one per cell
  double force_reduction = 0;           ///< ||T sigma|| / ||T sigma_d|| over free vertices (0 when sigma_d was balanced)
  double designed_force_mN = 0;         ///< ||T sigma_d|| over free vertices (kPa mm^2)
  double remaining_force_mN = 0;        ///< ||T sigma|| over free vertices: what the solve left
  int refinement_steps = 0;             ///< solves with the factor (preconditioned CG iterations); 0 when remembered
  /// Stopped for the picture (EquilibrationPass::picture): force_reduction is at most
  /// kPictureReduction but may exceed the complete pass's 1e-10; StressEquilibrator::finish() completes it.
  bool provisional = false;
};

/// How far one call equilibrates.
enum class EquilibrationPass {
  complete,  ///< to ||T sigma|| <= 5e-11 ||T sigma_d|| (1e-10 required)
  picture,   ///< may stop after the first solve with the factor when that reaches kPictureReduction
};

/// The largest ||T sigma|| / ||T sigma_d|| of a provisional result: 1e-6 of the design's forces
/// moves the body by 1e-6 of what the design would, 100x below the preview's solver tolerance.
inline constexpr double kPictureReduction = 1e-6;

class StressEquilibrator {
 public:
  /// Assembles Kc and factorizes Kc + eps I. The model must outlive the equilibrator and keep
  /// its topology and materials. `held_vertices` (Gamma_D) are held at rest: T sigma = 0 is
  /// imposed at the other vertices only, the held ones carry the reactions. InputError for ids
  /// out of range.
  explicit StressEquilibrator(const TissueModel& model, std::span<const VertexId> held_vertices = {});
  ~StressEquilibrator();
  StressEquilibrator(StressEquilibrator&&) noexcept;
  StressEquilibrator& operator=(StressEquilibrator&&) noexcept;

  /// Throws InputError when `designed_kPa` has the wrong size or non-finite values; ComputeError
  /// when ||T sigma|| / ||T sigma_d|| stays above 1e-10 (never returns NaN). Starts from the
  /// displacement of the previous call and the soft modes of the earlier ones (a small edit
  /// needs one or two solves with the factor; one of the last two designs, none).
  /// With EquilibrationPass::picture the result may be provisional (see above); a provisional
  /// result stays pending until finish() or the next equilibrate() call, which drops it (and
  /// starts from its displacement).
  EquilibrationResult equilibrate(std::span<const Vec6> designed_kPa, EquilibrationPass pass = EquilibrationPass::complete);
  /// True while a provisional result waits for finish().
  bool has_provisional() const;
  /// Completes the pending provisional result: the steps equilibrate() would have taken after its
  /// first (the same result, bit for bit, and remembered as it would be). InputError when none is
  /// pending; ComputeError as equilibrate().
  EquilibrationResult finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot equilibration (a StressEquilibrator used once).
EquilibrationResult equilibrate_stress(const TissueModel& model, std::span<const Vec6> designed_kPa,
                                       std::span<const VertexId> held_vertices = {});

}  // namespace cleave
