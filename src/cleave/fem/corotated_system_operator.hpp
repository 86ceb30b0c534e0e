#pragma once
// The dynamic step's system applied cell by cell, without its matrix (solve/vertex_operator.hpp):
//   A = c_stiff sum_c R_c K^e R_c^T + c_stress sum_c K_sigma,c + c_mass M,
// fixed dofs as identity rows and zero columns: the matrix Dynamics assembles (fem/dynamics.hpp)
// and eliminates. A product is two parallel passes: per cell, its 24 values
// R [c_stiff K^e + c_stress (sum_k t_k G_k) (x) I_3] R^T x_e (K^e per material and the six G_k
// in the cache; R and the tension t per cell); then per vertex, the sum over its cells plus the
// mass term. It streams the cells' rotations, tension and corners and a 24-value buffer per cell
// (about 12 MB at 44k cells in float) instead of the assembled blocks (53 MB in float, 106 MB in
// double), and a step no longer assembles the blocks at all. Where the CPU has AVX-512, the cell
// passes work in corner modes (fem/cube_corner_modes.hpp), where each 8 x 8 block of K^e and of
// the stress stiffness is a multiply and a lane permutation: float two cells per 16-float
// register, double one cell per 8-double register (fem/corotated_cells_avx512.hpp), reading the
// cell's 6 tension values. At 44k cells (session 35) the double product takes 1.1-1.25 ms
// instead of 1.3-1.5 with the dense blocks, the float one 0.6 ms instead of 0.75-0.8 (its gathers
// and permutations bind it, not its multiply-adds), against 0.9-1.1 ms for the portable pass,
// which reads an 8 x 8 stress stiffness per cell formed once per state.
//
//   CorotatedSystemOperator op;
//   op.set_topology(volume, table);                  // after construction and after every cut
//   op.set_state(rotations, tension, c_k, c_s, c_m, mass, fixed);   // every step
//   multiply(op, x, y);                              // float or double
//
// The volume, table, rotations, tension, mass and fixed flags are referenced and must outlive the
// products.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cleave/fem/cell_ranges.hpp"
#include "cleave/fem/corotated_cells_avx512.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/grid/vertex_corner_slots.hpp"
#include "cleave/solve/vertex_operator.hpp"

namespace cleave {

class CorotatedSystemOperator final : public VertexOperator {
 public:
  /// The volume's current cells and vertices and their materials (per vertex: its cells and its
  /// corner in each).
  void set_topology(const LinkedVolume& volume, const ElementTable& table);
  /// The step's state: `rotations` per cell (orthogonal: polar factors), `tension_kPa` per cell
  /// or empty (no stress stiffness), the coefficients c_stiff and c_stress (dimensionless) and
  /// c_mass (1/s^2), `mass_kg` and `fixed` per dof (referenced, like the rotations and tension).
  /// Throws InputError for sizes that do not fit the topology.
  void set_state(std::span<const Mat3> rotations, std::span<const Vec6> tension_kPa, double c_stiff, double c_stress,
                 double c_mass, const Vector& mass_kg, const std::vector<std::uint8_t>& fixed);

  Eigen::Index rows() const override { return 3 * static_cast<Eigen::Index>(corner_slots_.start.size() - 1); }
  void multiply(const Eigen::VectorXf& x, Eigen::VectorXf& y) const override;
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  /// In one pass with the product's per-vertex sum (the product's values never stored).
  void residual(const Eigen::VectorXf& b, const Eigen::VectorXf& x, Eigen::VectorXf& r) const override;
  void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const override;
  void jacobi_residual(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, const Eigen::VectorXf& x,
                       Eigen::VectorXf& z) const override;
  void jacobi_residual(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                       Eigen::VectorXd& z) const override;
  /// In one pass with the product's per-vertex sum: each vertex's x and d are updated once its
  /// sum is complete (the cell pass, which reads x, is done by then).
  void chebyshev_step(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, Eigen::VectorXf& x, Eigen::VectorXf& d,
                      float c_d, float c_z, Eigen::VectorXf& work) const override;
  void chebyshev_step(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, Eigen::VectorXd& x, Eigen::VectorXd& d,
                      double c_d, double c_z, Eigen::VectorXd& work) const override;
  std::vector<Mat3> inverse_diagonal_blocks() const override;
  SparseMatrix assembled_matrix() const override;
  const std::vector<std::uint8_t>& fixed_dofs() const override { return *fixed_; }
  /// Per vertex, its corners in the topology's cells for 24 values per cell (8 x, 8 y, 8 z): what
  /// other cell passes over the same topology sum their per-cell values with.
  const VertexCornerSlots& corner_slots() const { return corner_slots_; }
  /// Cells the products compute (set_state's): those with a corner whose dofs are not all fixed.
  std::size_t computed_cells() const;
  /// The same cells as [begin, end) ranges, for the last set_state's topology and fixed flags
  /// (the cells left out feed identity rows only; set_topology does not clear the list).
  const std::vector<CellRange>& computed_cell_ranges() const { return cell_ranges_; }

  /// The cell passes in AVX-512 (float: two cells per register; double: one)
  /// (fem/corotated_cells_avx512.hpp): on by default where the CPU has it. Throws InputError when
  /// asked for on a CPU without it. Off: the portable pass (one cell per 8-float register).
  void set_wide_cell_pass(bool on);
  bool wide_cell_pass() const { return wide_cell_pass_; }
  /// The AVX-512 passes run: they are on and the table's element matrices have the corner-mode
  /// form they compute with (fem/cube_corner_modes.hpp; any table of isotropic materials has
  /// it). Otherwise the portable pass runs.
  bool mode_cell_pass() const;

 private:
  /// Cell values by component: for component i (x, y, z), the 8 corners' values (a SIMD register
  /// of 8 floats), so that rotations and products run over the corners at once.
  template <typename Scalar>
  using Corners = Eigen::Matrix<Scalar, 8, 1>;
  template <typename Scalar>
  using CornerBlocks = std::array<Eigen::Matrix<Scalar, 8, 8>, 9>;  ///< [3 i + j](a, b) = K(3 a + i, 3 b + j)

  template <typename Scalar>
  struct Precision {
    std::vector<Eigen::Matrix<Scalar, 24, 24>> stiffness;  ///< per material slot: c_stiff K^e (double only: diagonal, assembly)
    std::vector<CornerBlocks<Scalar>> stiffness_by_component;  ///< the same, reordered
    std::array<Eigen::Matrix<Scalar, 8, 8>, 6> stress_basis;  ///< G_k
    std::vector<Eigen::Matrix<Scalar, 3, 3>> rotation;  ///< per cell (float only; double reads rotations_)
    std::vector<Eigen::Matrix<Scalar, 6, 1>> tension;   ///< per cell: c_stress t
    /// Per cell: its stress stiffness sum_k (c_stress t_k) G_k, formed once per state for the
    /// portable float pass (form_stress_stiffness; the mode pass reads the 6 tension values).
    mutable std::vector<Eigen::Matrix<Scalar, 8, 8>> stress_stiffness;
    std::vector<Scalar> stiffness_modes;  ///< per material slot: c_stiff K^e's 9 blocks in modes, 8 each
    std::vector<Scalar> stress_modes;     ///< the six G_k in modes, 8 each (fem/cube_corner_modes.hpp)
    Eigen::Matrix<Scalar, Eigen::Dynamic, 1> mass_term;  ///< per dof: c_mass m (0 on fixed dofs)
    mutable Eigen::Matrix<Scalar, Eigen::Dynamic, 1> masked;  ///< x with fixed dofs zeroed
    mutable std::vector<Scalar> per_cell;                     ///< 24 per cell: 8 x, 8 y, 8 z
  };
  /// The product's cell pass on x, then per vertex finish(v, (A x)_v).
  template <typename Scalar, typename Finish>
  void apply(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, const Finish& finish) const;
  /// Per vertex v: finish(v, sum) with sum the per-cell values summed at v plus the mass term
  /// (x_masked: x with fixed dofs zero), x_in's value on fixed dofs (identity rows).
  template <typename Scalar, typename Finish>
  void sum_per_vertex(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x_in,
                      const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x_masked, const Finish& finish) const;
  template <typename Scalar>
  void fused_chebyshev_step(const Precision<Scalar>& p, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                            const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                            Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& d, Scalar c_d, Scalar c_z) const;
  template <typename Scalar>
  void fused_residual(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                      const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& r) const;
  template <typename Scalar>
  void fused_jacobi_residual(const Precision<Scalar>& p, const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                             const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                             Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) const;
  template <typename Scalar>
  const Eigen::Matrix<Scalar, 3, 3>& rotation_of(const Precision<Scalar>& p, std::size_t cell) const;
  /// The coefficient of I_3 in block (a, b) of cell c's stress stiffness, times c_stress.
  double stress_coefficient(std::size_t cell, int a, int b) const;

  /// A corner's diagonal block of c_stiff K^e on the cube: isotropic I + along_sign s s^T, s the
  /// corner's outward signs (+-1 per axis), exactly so for an isotropic material (the integrals
  /// of dN_a/dx_i dN_a/dx_j are equal over i != j up to those signs). Its rotated block is then
  /// isotropic I + along_sign (R s)(R s)^T for a rotation R (R R^T = I): the block diagonal
  /// (every step, for the smoother) costs 1.6 ms at 44k cells instead of 2.9 with the general
  /// triple product.
  struct CornerDiagonal {
    double isotropic = 0;
    double along_sign = 0;
  };
  /// Per material slot, per corner; empty where a material's blocks do not split so (then the
  /// block diagonal takes the general product).
  std::vector<std::array<CornerDiagonal, 8>> corner_diagonal_;
  /// Per corner a: G_k(a, a) for the 6 components k (the stress stiffness's diagonal, gathered).
  std::array<Eigen::Matrix<double, 6, 1>, 8> stress_diagonal_basis_{};
  void split_corner_diagonals();

  /// The element table's K^e per material and G_k in corner modes (fem/cube_corner_modes.hpp);
  /// empty where they do not have that form.
  std::vector<std::array<Eigen::Matrix<double, 8, 1>, 9>> stiffness_modes_;
  std::optional<std::array<Eigen::Matrix<double, 8, 1>, 6>> stress_modes_;
  template <typename Scalar>
  void set_mode_coefficients(Precision<Scalar>& p, double c_stiff) const;
  /// single_.stress_stiffness, for the portable float pass, once per state.
  void form_stress_stiffness() const;

  const LinkedVolume* volume_ = nullptr;
  const ElementTable* table_ = nullptr;
  std::vector<std::uint8_t> material_;        ///< per cell: slot in table.per_material
  VertexCornerSlots corner_slots_;  ///< per vertex: slots 24 c + a (cell c, corner a), its x in per_cell
  std::span<const Mat3> rotations_;
  bool with_tension_ = false;
  const std::vector<std::uint8_t>* fixed_ = nullptr;
  std::vector<Eigen::Index> fixed_rows_;   ///< the fixed dofs, listed (empty: none held)
  std::vector<std::uint8_t> fixed_seen_;   ///< the flags fixed_rows_ lists (set_state compares)
  /// Per vertex: all three dofs fixed (its rows are identity rows: no cell sum is needed).
  std::vector<std::uint8_t> vertex_held_;
  /// The cells the passes compute, in ranges of at most kCellsPerTask: those with a corner that
  /// is not held (a cell held at all 8 corners feeds identity rows only; the studio's cut model
  /// has 7,520 of 45,796 so, its removed plugs and supports).
  std::vector<CellRange> cell_ranges_;
  /// vertex_held_ and cell_ranges_ for the fixed flags fixed_seen_.
  void list_held_cells();
  double c_mass_ = 0;  ///< c_stiff and c_stress are folded into stiffness and tension
  const Vector* mass_kg_ = nullptr;
  bool wide_cell_pass_ = avx512_cell_pass_supported();
  Precision<float> single_;
  Precision<double> twin_;
};

}  // namespace cleave
