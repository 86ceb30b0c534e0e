#pragma once
// Corotational linear elasticity with residual stress, integrated implicitly by the HHT-alpha
// method (Hilber-Hughes-Taylor, a Newmark family member with numerical damping):
//   M u'' + D u' + f_int(u) = f_ext,   D = alpha M + beta_R K_R,   M lumped,
// with the damping and elastic forces taken as w [.](n+1) + (1 - w) [.](n), w = 1 - a,
// gamma = 1/2 + a, beta = (1 + a)^2 / 4, a = `numerical_damping` in [0, 1/3]. a = 0 is the average
// acceleration rule (no numerical damping, energy conserved for linear elasticity). The default
// a = 0.2 damps what the time step cannot resolve (a one-cell piece ringing at kHz with dt = 1 ms)
// and keeps second-order accuracy for what it resolves (the 25 ms cantilever mode at dt = 1 ms
// loses 1.3 % of its energy per period). Why: with R frozen over a step, the undamped rule feeds
// energy into fast rotating pieces; a cell cut loose or hanging by one face under 20 kPa grew to
// 1e80 mm in 300 steps (tests/fem/extreme_values_test.cpp); at a = 0.1 it still swung, at 0.2 it rests.
// `high_frequency_radius` switches to generalized-alpha (Chung & Hulbert 1993: the inertia is
// weighted between n and n + 1 too), which can remove what the step cannot resolve entirely
// (radius 0): the studio's wound opening at 30 ms steps, whose own modes are 3 ms fast.
// What rotates: each cell c has the rotation R_c of the polar decomposition of its deformation
// gradient at the cell centre. Its element force is
//   f_e = R_c [ K^e (R_c^T x_e - X_e) + T^e sigma_c ],
// i.e. the linear elastic force and the residual stress force are evaluated in the cell's
// unrotated (reference) frame and rotated into the world: the residual stress tensor is attached
// to the material and turns with it. The step linearizes f_int at the current state with R fixed
// (stiffness K_R = sum R K^e R^T) and solves one linear system per step with the chosen solver,
// warm-started from the Newmark predictor of the previous state. The multigrid takes the system
// as an operator applied cell by cell (fem/corotated_system_operator.hpp; after cuts too), so a
// step assembles nothing between the multigrid's rebuilds. Where a matrix is needed (a rebuild,
// CHOLMOD, Eigen's CG, matrix_free off), K_R is re-gathered in place, as block CSR, on a pattern
// patched for the rows cuts touched, and the solver is only told the new values
// (LinearSolver::update_block_values / update_values: the multigrid keeps its levels, CHOLMOD
// its analysis).
//
//   Dynamics sim(model, stress_kPa, settings);   // model must outlive sim
//   for (int i = 0; i < n; ++i) sim.step(1e-3);
//   CutReport r = model.volume.cut_links(links); sim.topology_changed(r);   // then step on
//
// Pieces cut free keep their momentum (no gravity unless given; mass damping alpha slows them).
// Errors: ComputeError (with the residual reached) when a step's solve does not converge, and
// when the motion diverges (a vertex moves more than kDivergedSizes times the model's size).
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cleave/fem/corotated_forces.hpp"
#include "cleave/fem/corotated_system_operator.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

inline constexpr double kNewmarkGamma = 0.5;  ///< average acceleration; plus numerical_damping
/// A displacement this many times the model's bounding-box diagonal means the motion diverged.
inline constexpr double kDivergedSizes = 1000.0;
/// The iteration budget of a real-time step (DynamicsSettings::iterations_per_step) that the
/// studio's wound opening and `cleave bench`'s step_budget use.
inline constexpr int kRealTimeIterationsPerStep = 5;

struct DynamicsSettings {
  SolverKind solver = SolverKind::multigrid_cg;
  SolveSettings solve;
  /// The step's solve also stops when its force residual is below this times the residual it
  /// starts from (SolveSettings::initial_residual_tolerance, which this sets). It starts from the
  /// Newmark predictor, or from no increment where that is closer in the energy norm
  /// (SolveSettings::zero_start_when_better): at display rates the predictor's acceleration term
  /// overshoots the stiff modes (after a cut on the 44k tube its residual was 1e3-1e4 times that
  /// of no increment, and steps stopped at 1e-5 of it were off by up to 7 % of the motion on the
  /// bench's cut, up to 110 % on the abdomen's opening at dt = 0.03 s; from the better start 2e-4).
  /// 0: stop at solve.relative_tolerance of the whole right-hand side alone.
  double step_tolerance = 1e-5;
  /// At most this many solver iterations per step (0: no budget, every step solves to
  /// step_tolerance). With a budget a step that has not met step_tolerance is taken as it is, as
  /// real-time multigrid simulators do (Dick, Georgii & Westermann 2011 run a fixed number of
  /// cycles per frame): the force imbalance it leaves is in the next step's right-hand side, so
  /// the motion lags the exact one a little and comes to rest at the same equilibrium. The
  /// studio's wound opening runs so, with kRealTimeIterationsPerStep per step.
  /// A budgeted multigrid step smooths its fine level with one damped block-Jacobi step before
  /// and after the coarse correction (Chebyshev degree 1 over [lambda_max / 4, lambda_max])
  /// instead of degree 2: 3 fine products an iteration instead of 5, and 5 iterations instead of
  /// 4 in less time. Against steps solved to 1e-5, after 24 steps with a cut growing over the
  /// first 14, the largest vertex error (median over the steps, of the largest displacement) was
  /// 1.2e-2 for both on the 44k tube, 9.2e-3 against 2.1e-2 on the 45k abdomen. After a cut its
  /// fine smoother's bound continues with 2 power iterations instead of 4 (never lowered).
  /// A budgeted multigrid still rebuilds stale levels: it extrapolates the iterations a step
  /// would have needed from the rate it reached (iterations_at_reached_rate); during a growing cut
  /// that is every 3-5 steps, each such step 3-4 times as long (the harness
  /// DISABLED_BudgetAccuracy prints them). A non-finite residual or a diverged motion still throws.
  int iterations_per_step = 0;
  double mass_damping_per_s = 0;        ///< Rayleigh alpha (1/s)
  double stiffness_damping_s = 0;       ///< Rayleigh beta (s)
  std::vector<VertexId> fixed_vertices; ///< held at zero displacement (vertices split off them too)
  Vec3 gravity_mm_per_s2 = Vec3::Zero();
  double numerical_damping = 0.2;       ///< HHT alpha = -this (0 to 1/3): gamma = 1/2 + this, beta = (1 + this)^2 / 4
  /// Set (0 to 1): the generalized-alpha rule (Chung & Hulbert 1993) instead of HHT, with this
  /// spectral radius for what the time step cannot resolve: the inertia taken at n + 1 -
  /// alpha_inertia, alpha_inertia = (2 r - 1) / (r + 1), the forces at n + 1 - alpha_forces,
  /// alpha_forces = r / (r + 1) (numerical_damping is then unused). HHT's radius there is
  /// (1 - a) / (1 + a) = 0.67 at a = 0.2, and such modes decay slowly at first: a wound opening at
  /// 30 ms steps (its modes cross the cut in 3 ms) alternated by +-20 % of its width frame to
  /// frame for 8 frames. r = 0 removes them by the third step; resolved motion stays second-order
  /// accurate but is damped too (a cantilever mode at omega dt = 0.25 keeps 0.67 of its energy
  /// over 4 periods); r = 1 is the undamped average-acceleration motion.
  std::optional<double> high_frequency_radius;
  Vector external_force_mN;             ///< constant nodal forces (3 n_v); empty = none
  /// With residual stress, the step's system includes the initial-stress stiffness of the tension
  /// each cell carries (residual plus elastic, fem/stress_stiffness.hpp): the change of the stress
  /// forces as cells rotate, which the frozen-rotation step misses. false (and stress-free bodies):
  /// the classic corotational step, which a free shell under unbalanced tension of the order of E
  /// made diverge within 0.2-0.5 s at dt = 1/60 s.
  bool stress_stiffness = true;
  /// The step's system is applied cell by cell (fem/corotated_system_operator.hpp) where the
  /// solver takes it so (the multigrid, between its rebuilds): no assembly of its blocks, and
  /// products that read the cells' rotations instead of the 3x3 blocks; steps after a cut too.
  /// The assembled matrix is still gathered for the first step, a rebuild and the other solvers.
  /// false: assembled every step (the reference path: both solve the same system).
  bool matrix_free = true;
};

class Dynamics {
 public:
  /// Starts at rest (u = 0, u' = 0) on the model's current topology. `residual_stress_kPa` is
  /// empty (stress free) or one tensor per cell. Throws InputError for mismatched sizes or
  /// negative damping.
  Dynamics(const TissueModel& model, std::vector<Vec6> residual_stress_kPa, DynamicsSettings settings);
  ~Dynamics();
  Dynamics(const Dynamics&) = delete;
  Dynamics& operator=(const Dynamics&) = delete;

  /// Advances by dt (s > 0). Returns the linear solve's report.
  SolveReport step(double dt_s);

  /// Call after model.volume.cut_links(...) returned `report`: new vertices take the displacement
  /// and velocity of the vertex they split off; mass, forces and the stiffness pattern follow the
  /// new topology, and the acceleration is recomputed from them (forces jump at a cut).
  void topology_changed(const CutReport& report);

  /// Replaces the state (3 n_v each; mm, mm/s) and recomputes the acceleration.
  void set_state(const Vector& displacement_mm, const Vector& velocity_mm_per_s);

  const Vector& displacement() const { return u_; }  ///< 3 n_v, mm
  const Vector& velocity() const { return v_; }      ///< 3 n_v, mm/s
  std::vector<Vec3> displacement_mm() const;
  double time_s() const { return time_s_; }
  std::string_view solver_name() const;
  const std::vector<std::uint8_t>& fixed_dofs() const { return fixed_; }
  /// Steps whose system the solver took as the cell-by-cell operator (DynamicsSettings::matrix_free).
  int matrix_free_steps() const { return matrix_free_steps_; }
  /// Cells whose rotation, tension and forces the last step computed: with the operator, a step
  /// after the first on a topology leaves out the cells held at every corner (their forces act
  /// on held dofs only, and the held dofs' rows are identity rows; the studio's cut model has
  /// 7,520 of 45,796 so).
  std::size_t cells_in_last_step() const { return cells_in_last_step_; }

  /// 1/2 v^T M v (uJ = kg mm^2 / s^2 = mN mm).
  double kinetic_energy_uJ() const;
  /// Corotated strain energy plus residual stress work: sum over cells of
  /// 1/2 d^T K^e d + d^T T^e sigma with d = R^T x_e - X_e (uJ).
  double elastic_energy_uJ() const;

 private:
  /// Mass and operator topology of the current topology, and the system pattern and gather table
  /// (at once without a cut or with matrix_free off, else at the next assembly); `cut`: the cut since the
  /// last call (its untouched rows keep their pattern), null for a fresh one.
  void rebuild_topology(const CutReport* cut = nullptr);
  /// Makes system_, system_blocks_, gather_ and diagonal_block_ follow the current topology
  /// (after cuts: the rows in rows_to_pattern_ afresh, the others kept).
  void ensure_pattern();
  /// Every vertex created since the solver's last update has a known origin among its vertices.
  bool origins_known() const;
  /// Records, for every vertex the cut created, the vertex the solver knew it as (origin_of_new_).
  void note_vertex_origins(const CutReport& report);
  void update_rotations();
  /// f_int + beta_k K_R v: the elastic and residual stress forces and, with stiffness damping, the
  /// damping force of `velocity` from the same per-cell pass (K_R is never assembled for it).
  /// `cell_ranges`: only those cells' forces are computed afresh (the others' stay as the last
  /// pass left them); null: every cell.
  Vector internal_forces(const Vector* velocity = nullptr,
                         const std::vector<CellRange>* cell_ranges = nullptr) const;
  Vector external_forces() const;
  /// system_blocks_ = c_stiff K_R + c_stress K_sigma + c_mass M in one gather (no separate K_R,
  /// no scaling pass); K_sigma from tension_kPa_.
  void assemble_system(double c_stiff, double c_stress, double c_mass);
  /// Gives the solver the assembled system (mass term c_mass): block values where it takes
  /// them; else, for a matrix-free set-up, system_operator_ (its state set) with the blocks to
  /// build from (the multigrid's rebuilds: no scalar copy, no fine-level copy, the step applied
  /// cell by cell); else system_.
  void hand_system_to_solver(double c_mass);
  /// Gives the solver the system as system_operator_ (its state set; no assembly) where it takes
  /// it: the topology and the mass term are those it was last given. false: assemble.
  bool hand_operator_to_solver(double c_mass);
  void compute_acceleration();

  const TissueModel& model_;
  std::vector<Vec6> stress_kPa_;
  DynamicsSettings settings_;
  ElementTable table_;
  std::unique_ptr<LinearSolver> solver_;

  Vector mass_;    ///< lumped, per dof (kg)
  std::vector<std::uint8_t> fixed_;
  /// c_k K_R + c_m M with fixed dofs eliminated, as block CSR: assembled every step (what the
  /// multigrid multiplies with: LinearSolver::update_block_values, which exchanges its values
  /// with the solver's older ones; every step overwrites all of them).
  BlockSparseMatrix<double> system_blocks_;
  VertexBlockGather gather_;                 ///< where each cell's blocks go in system_blocks_
  CorotatedSystemOperator system_operator_;  ///< the same system applied cell by cell
  CorotatedForcePass force_pass_;            ///< the cells' elastic and stress forces
  mutable std::vector<double> force_per_cell_;  ///< internal_forces' per-cell corner forces (kept: no fresh pages per step)
  mutable Vector damped_displacement_;          ///< u + beta_k v for the force pass (kept likewise)
  std::vector<std::int32_t> diagonal_block_;  ///< per vertex: its diagonal block in system_blocks_
  /// The same matrix as scalar CSR (vertex block pattern of the topology), made and filled from
  /// the blocks only when a solver asks for it (CHOLMOD, Eigen's CG, the assembled steps).
  SparseMatrix system_;
  bool scalar_current_ = false;  ///< system_ has the pattern of system_blocks_
  bool any_fixed_ = false;
  /// The block pattern (system_blocks_, gather_, diagonal_block_) is that of the current
  /// topology; after cuts it is rebuilt only when a step assembles.
  bool pattern_current_ = false;
  std::vector<std::uint8_t> rows_to_pattern_;  ///< per vertex: a row the cuts since the pattern touched
  /// The next step computes every cell's rotation, tension and forces (a new topology, or none
  /// yet): the operator's list of the cells it computes is that of the last step's state.
  bool every_cell_next_step_ = true;
  std::size_t cells_in_last_step_ = 0;
  bool solver_ready_ = false;  ///< set up (later steps update values, or the topology after a cut)
  VertexId solver_vertices_ = 0;  ///< vertex count of the topology the solver last saw
  /// Per vertex created by cuts since then (id solver_vertices_ + i): the vertex it was copied
  /// from, as the solver knew it (kNone: unknown, the solver is set up afresh).
  std::vector<VertexId> origin_of_new_;
  double solver_mass_factor_ = 0;  ///< c_m of the matrix the solver was set up with (1/s^2)
  std::vector<Mat3> rotations_;
  std::vector<Vec6> tension_kPa_;  ///< per cell, for the stress stiffness (empty: not included)
  Vector u_, v_, a_;
  double time_s_ = 0;
  int matrix_free_steps_ = 0;
};

}  // namespace cleave
