#pragma once
// Solvers take operators, not models: a symmetric positive (semi-)definite sparse matrix on the
// vertex degrees of freedom of a linked volume (dof 3 * vertex + axis), plus that volume for the
// geometric multigrid. Fixed (Dirichlet) dofs arrive already eliminated: their row and column are
// zero except a 1 on the diagonal, and their right-hand side entry holds the prescribed value.
#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <string_view>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Vector = Eigen::VectorXd;
template <typename Scalar>
struct BlockSparseMatrix;  // block_sparse_matrix.hpp
class VertexOperator;      // vertex_operator.hpp

enum class SolverKind {
  multigrid_cg,  ///< cleave's default: CG preconditioned by a cut-aware geometric multigrid V-cycle
  eigen_cg,      ///< peer: Eigen's ConjugateGradient with incomplete Cholesky
  cholmod,       ///< peer: SuiteSparse CHOLMOD sparse Cholesky (direct)
};

/// "multigrid", "eigen-cg", "cholmod" <-> SolverKind. Throws InputError listing the names.
SolverKind solver_kind_from_name(std::string_view name);
std::string_view solver_kind_name(SolverKind kind);

struct SolveSettings {
  double relative_tolerance = 1e-8;  ///< stop when ||b - A x|| <= tol * ||b||
  /// Also stop when ||b - A x|| <= this * ||b - A x0||, x0 the initial guess: the residual relative
  /// to what the warm start left (the dynamic step's correction of its Newmark predictor). 0: off.
  /// Read by the CG solvers of cleave (multigrid); the peers solve to relative_tolerance.
  double initial_residual_tolerance = 0;
  /// CG starts from x = 0 instead of the given guess when the guess is farther from the solution
  /// in the energy norm ||x - x*||_A (from the guess's residual r: when x^T (b + r) < 0, two dot
  /// products). The dynamic step sets it: its Newmark predictor carries the step's whole
  /// unopposed acceleration into the stiff modes, which at display rates (dt = 1/60 s) and after
  /// cuts left residuals of 1e3-1e4 ||b|| on the 44k tube, while it is exact for free fall and
  /// close for slow motion. The reported initial residual is the start's. Read by the CG solvers
  /// of cleave (multigrid); the peers solve to relative_tolerance.
  bool zero_start_when_better = false;
  int max_iterations = 2000;
  /// CG on an operator applied cell by cell (solve/vertex_operator.hpp): the product of each
  /// iteration (q = A p) in single precision, half the arithmetic of the double one; the residuals
  /// that decide convergence (at the start, and the true residual at the end, from which CG
  /// restarts when the recurrence drifted) stay in double. The multigrid sets it for the dynamic
  /// step while its cycle runs in single precision. Off: every product in double.
  bool single_precision_products = false;
  /// cholmod: forward and back substitution with the factor on all cores (SupernodalSubstitution,
  /// cleave's own); false: cholmod_solve as SuiteSparse ships it (the bench's peer).
  bool parallel_substitution = true;
  /// cholmod with parallel_substitution: also keep the factor's values in single precision and
  /// substitute with them (half the bytes streamed), refining in double residuals until
  /// relative_tolerance is met; the double factor solves when three substitutions do not. Pays
  /// where one float substitution meets the tolerance (the studio's preview at 1e-4: residuals of
  /// 9e-6 and 1.2e-5 on the incised abdomen and tube at 45k cells); costs memory for the copy
  /// (half the factor's: 0.5 GB there).
  bool single_precision_factor = false;
};

struct SolveReport {
  int iterations = 0;
  double relative_residual = 0;  ///< ||b - A x|| / ||b|| reached
  double initial_relative_residual = 0;  ///< ||b - A x0|| / ||b|| of the initial guess (CG solvers; 0 otherwise)
  bool converged = false;  ///< relative_residual <= relative_tolerance, or the initial_residual_tolerance rule met
  /// Multigrid: of the iterations, those with the double-precision cycle (after float rounding
  /// stalled the single-precision one, or when it was built so).
  int double_cycle_iterations = 0;
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// Prepares for A (factorization, hierarchy). `topology` is the linked volume whose vertices
  /// the dofs belong to; it must stay alive and unchanged until the next setup.
  virtual void setup(const SparseMatrix& a, const LinkedVolume& topology) = 0;
  /// setup() with a matrix the caller gives away (StaticSolver's eliminated stiffness, ~1 GB at
  /// 350k cells): a solver that keeps the scalar matrix takes this one instead of copying it.
  /// The default sets up from it as setup() does.
  virtual void setup_taking(SparseMatrix&& a, const LinkedVolume& topology) { setup(a, topology); }
  /// Like setup() for a matrix with the same sparsity pattern and topology as the last setup and
  /// new values (the next time step's corotated stiffness). Solvers keep what depends only on
  /// the pattern (CHOLMOD's symbolic analysis, the multigrid's levels, which it refreshes only
  /// when its iterations grow: a stale preconditioner still gives the exact solution).
  /// The default sets up from scratch.
  virtual void update_values(const SparseMatrix& a, const LinkedVolume& topology) { setup(a, topology); }
  /// Like update_values() after cuts divided vertices: `a` is the matrix of the new topology, in
  /// which vertex `n + i` (n = the vertex count of the last setup) is a copy of vertex
  /// `origin_of_new[i]` (< n) and every other vertex keeps its id. A cut leaves the cells'
  /// element matrices unchanged, so with each copy's prolongation row taken from its origin the
  /// multigrid's kept coarse levels are exactly the Galerkin operators of the new matrix
  /// (P'^T A' P' = P^T A P); it rebuilds only its fine level. The default sets up from scratch.
  virtual void update_topology(const SparseMatrix& a, const LinkedVolume& topology, const std::vector<VertexId>& origin_of_new) {
    (void)origin_of_new;
    setup(a, topology);
  }
  /// Like update_values() with the new values given as block CSR (3x3 vertex blocks) of the
  /// pattern of the last setup, for solvers that multiply with block CSR anyway (the multigrid):
  /// no scalar CSR needs to exist for them. The solver takes the values without copying them: it
  /// exchanges them with its previous ones, so on return `a` keeps its pattern and holds values
  /// of an older matrix (the caller overwrites them for the next update). Returns false, and
  /// takes nothing, when the solver needs the scalar matrix for this update (a rebuild is due,
  /// or it works on scalar CSR): the caller then calls update_values() with it.
  virtual bool update_block_values(BlockSparseMatrix<double>& a, const LinkedVolume& topology) {
    (void)a;
    (void)topology;
    return false;
  }
  /// Like update_block_values() with the new matrix applied without its values (the dynamic
  /// step's corotated system, same topology and fixed dofs as the last update): the solver
  /// multiplies with `a` until the next update (it is referenced and must outlive the solves).
  /// Returns false, and takes nothing, when the solver needs the assembled matrix for this update
  /// (a rebuild is due, or it cannot work without it: the default).
  virtual bool update_operator(const VertexOperator& a, const LinkedVolume& topology) {
    (void)a;
    (void)topology;
    return false;
  }
  /// Like update_topology() with the new matrix applied without its values (as update_operator):
  /// vertex n + i of `a` is a copy of vertex origin_of_new[i]. false (the default): the solver
  /// needs the assembled matrix for this update.
  virtual bool update_topology_operator(const VertexOperator& a, const LinkedVolume& topology,
                                        const std::vector<VertexId>& origin_of_new) {
    (void)a;
    (void)topology;
    (void)origin_of_new;
    return false;
  }
  /// setup() for a matrix applied without its values from now on (as update_operator; `a` is
  /// referenced and must outlive the solves), given also assembled as block CSR (`blocks`, the
  /// same values, fixed dofs eliminated) for what needs its entries: the multigrid builds its
  /// coarse levels from them and keeps no copy. Any topology (no relation to the last setup).
  /// false (the default), with nothing done: the solver needs the scalar matrix (setup()).
  virtual bool setup_operator(const VertexOperator& a, const BlockSparseMatrix<double>& blocks, const LinkedVolume& topology) {
    (void)a;
    (void)blocks;
    (void)topology;
    return false;
  }
  /// update_topology() with the new matrix also given as block CSR (the same values, its block
  /// pattern): the multigrid then takes the blocks instead of converting `a`. The default ignores
  /// them.
  virtual void update_topology_with_blocks(const SparseMatrix& a, const BlockSparseMatrix<double>& blocks,
                                           const LinkedVolume& topology, const std::vector<VertexId>& origin_of_new) {
    (void)blocks;
    update_topology(a, topology, origin_of_new);
  }
  /// Solves A x = b; x holds the initial guess on entry (warm start) and the solution on exit.
  /// Never leaves NaN in x: on divergence x keeps its last finite iterate and converged = false.
  virtual SolveReport solve(const Vector& b, Vector& x) = 0;
  virtual std::string_view name() const = 0;
};

std::unique_ptr<LinearSolver> make_linear_solver(SolverKind kind, const SolveSettings& settings = {});

}  // namespace cleave
