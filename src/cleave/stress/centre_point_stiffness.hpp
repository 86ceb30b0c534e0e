#pragma once
// The equilibration's one-point stiffness (stress/equilibrate_stress.hpp)
//   Kc = sum over cells of V Bc^T D Bc    (Bc: the strain matrix at the cube's centre)
// applied cell by cell, without its matrix. Bc holds only the centre gradients g_x, g_y, g_z of
// the 8 shape functions (+-1/(4h)), so a cell's part is 9 short dot products for its strain, D for
// its stress s = V D Bc u_e and 9 multiply-adds for its corner forces Bc^T s; a second pass sums
// them per vertex. A product streams the corners and a 24-value buffer per cell (~10 MB at 44k
// cells) instead of the assembled matrix (~140 MB), on all cores. Held dofs are identity rows and
// zero columns, as in the assembled matrix the equilibrator factorizes.
//
//   CentrePointStiffness kc(model.volume, make_element_table(model), held_dof);
//   SparseMatrix a = kc.assembled();       // for the factorization
//   kc.residual(b, u, r);                  // r = b - Kc u
//   kc.add_stress(u, stress_kPa);          // stress_c += D Bc u_e
//
// The volume is referenced and must keep its topology while the operator is used.
#include <cstdint>
#include <span>
#include <vector>

#include "cleave/fem/element_table.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

class CentrePointStiffness {
 public:
  /// `held_dof`: one flag per dof (3 per vertex), 1 = held. InputError when its size does not fit
  /// the volume or a cell's label has no material in `table`.
  CentrePointStiffness(const LinkedVolume& volume, const ElementTable& table, std::span<const std::uint8_t> held_dof);

  Eigen::Index rows() const { return static_cast<Eigen::Index>(held_.size()); }

  /// The matrix itself (symmetric, both triangles stored; held dofs as identity rows and columns).
  SparseMatrix assembled() const;
  /// y = Kc x. InputError for a vector of the wrong size.
  void multiply(const Vector& x, Vector& y) const;
  /// r = b - Kc x.
  void residual(const Vector& b, const Vector& x, Vector& r) const;
  /// stress_c += D_c Bc u_e for every cell (the compatible stress of the displacement u, kPa; the
  /// held dofs' values count as they are).
  void add_stress(const Vector& u, std::span<Vec6> stress_kPa) const;

 private:
  using Corners = Eigen::Matrix<double, 8, 1>;
  /// The cell's stress D Bc u_e from its corners' values of x.
  Vec6 cell_stress(CellId c, const Vector& x) const;
  void check_size(const Vector& x) const;

  const LinkedVolume& volume_;
  double cell_volume_mm3_;
  Corners gradient_x_, gradient_y_, gradient_z_;  ///< centre gradients of the 8 shape functions (1/mm)
  std::vector<Mat6> elasticity_kPa_;               ///< per material slot
  std::vector<std::uint8_t> material_;             ///< per cell: its material slot
  std::vector<std::uint8_t> held_;                 ///< per dof
  bool any_held_ = false;
  std::vector<std::int32_t> vertex_start_;         ///< see grid/vertex_corner_slots.hpp
  std::vector<std::int32_t> vertex_slot_;
  mutable Vector masked_;                          ///< x with held dofs zeroed
  mutable std::vector<double> per_cell_;           ///< 24 per cell: 8 x, 8 y, 8 z forces
};

}  // namespace cleave
