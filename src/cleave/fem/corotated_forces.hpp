#pragma once
// The cells' corotated elastic and stress forces, R [K^e (R^T (X_e + x_e) - X_e) + T^e s] per
// cell, into 24 values per cell (8 x, 8 y, 8 z: the layout the corotated operator's corner slots
// sum per vertex). x is the displacement, plus beta_k times a velocity for stiffness damping (the
// damping force R K^e R^T v shares K^e and R with the elastic one). Where the CPU has AVX-512 and
// the element matrices have the corner-mode form (fem/cube_corner_modes.hpp), one cell per
// 8-double register in modes (fem/corotated_cells_avx512.hpp); else one cell at a time with the
// dense K^e.
//
//   CorotatedForcePass forces;
//   forces.set_topology(volume, table);   // after construction and after every cut
//   forces.per_cell(rotations, stress_kPa, x_mm, per_cell);
//
// The volume and table are referenced and must outlive the passes.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "cleave/fem/cell_ranges.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

class CorotatedForcePass {
 public:
  /// The volume's cells and their materials, and the table's matrices in modes.
  void set_topology(const LinkedVolume& volume, const ElementTable& table);
  /// per_cell (resized to 24 per cell): each cell's forces (mN) for `rotations` and `x_mm` (3 per
  /// vertex) and its stress `stress_kPa` (Voigt; empty: none). Throws InputError for sizes that
  /// do not fit the topology.
  void per_cell(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm,
                std::vector<double>& per_cell) const;
  /// The same for the cells of `cell_ranges` ([begin, end) pairs) only; the other cells' 24
  /// values stay as they were (per_cell must already hold 24 per cell: InputError otherwise).
  void per_cell(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm,
                std::span<const CellRange> cell_ranges, std::vector<double>& per_cell) const;

  /// The AVX-512 mode pass (on where it can run); off: the dense pass. Throws InputError when
  /// asked for where it cannot run.
  void set_mode_pass(bool on);
  bool mode_pass() const { return mode_pass_; }

 private:
  /// Throws InputError when the sizes do not fit the topology.
  void check_sizes(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm) const;
  /// Cells [begin, end) into out (24 per cell).
  void cells_in_range(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm, std::size_t begin,
                      std::size_t end, std::vector<double>& out) const;

  const LinkedVolume* volume_ = nullptr;
  const ElementTable* table_ = nullptr;
  std::vector<std::uint8_t> material_;     ///< per cell: slot in table.per_material
  std::vector<double> stiffness_modes_;    ///< per material slot: K^e's 9 blocks in modes, 8 each
  std::array<double, 144> stress_divergence_{};  ///< T^e by component: [8 (3 k + i) + a] = T^e(3 a + i, k)
  bool modes_available_ = false;  ///< the CPU has AVX-512 and the matrices the mode form
  bool mode_pass_ = false;
};

}  // namespace cleave
