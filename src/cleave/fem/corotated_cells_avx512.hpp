#pragma once
// The cell passes of the corotated system's product (fem/corotated_system_operator.hpp) in
// AVX-512. Float: two cells per 16-lane register, lanes 0-7 the first cell's 8 corners, lanes 8-15
// the second's; double: one cell per 8-lane register. The corners' values are taken into modes
// (three butterfly stages of the Walsh-Hadamard transform in the lanes), where each 8 x 8 block
// of the element matrices is a multiply and a lane permutation (fem/cube_corner_modes.hpp), and
// back. The portable pass (AVX2 through Eigen, one cell per 8-float register) computes the same
// product with the dense blocks. Call it only where the operator's element matrices have the
// mode form (isotropic materials on cubes: always, for an ElementTable).
//
// Only this file's .cpp is compiled for AVX-512, and it includes no Eigen and no inline code it
// could share with the rest of the library (an AVX-512 copy of a shared inline function could be
// the one the linker keeps). Call it only where avx512_cell_pass_supported() is true.
//
//   CorotatedCellsInput in{...};
//   if (avx512_cell_pass_supported()) corotated_cells_avx512(in, begin, end);
#include <cstddef>
#include <cstdint>

namespace cleave {

/// What the cell pass reads and writes, as plain arrays (layouts of the operator's members).
/// The element matrices come in corner modes (fem/cube_corner_modes.hpp): per block, 8
/// coefficients and a fixed pairing of modes instead of 64 entries.
struct CorotatedCellsInput {
  const float* x = nullptr;                  ///< 3 per vertex (fixed dofs already zero)
  const std::int32_t* corners = nullptr;     ///< 8 vertex ids per cell
  const float* rotation = nullptr;           ///< 9 per cell: R column-major, R(i, j) at 3 j + i
  const std::uint8_t* material = nullptr;    ///< per cell: its material slot
  /// Per material slot: 9 blocks [3 i + j] of 8 mode coefficients of c_stiff K^e
  /// (corner_mode_form: divided by 64).
  const float* stiffness_modes = nullptr;
  const float* stress_modes = nullptr;       ///< the six G_k's 8 mode coefficients each (divided by 64)
  const float* tension = nullptr;            ///< 6 per cell (c_stress t, Voigt), or null (no tension)
  float* per_cell = nullptr;                 ///< out: 24 per cell, its corners' 8 x, 8 y, 8 z
};

/// The double cell pass's arrays: as CorotatedCellsInput in double.
struct CorotatedCellsInputDouble {
  const double* x = nullptr;
  const std::int32_t* corners = nullptr;
  const double* rotation = nullptr;
  const std::uint8_t* material = nullptr;
  const double* stiffness_modes = nullptr;
  const double* stress_modes = nullptr;
  const double* tension = nullptr;
  double* per_cell = nullptr;
};

/// What the force pass reads and writes (fem/dynamics.hpp's internal forces): per cell
/// R [K^e (R^T (X_e + x_e) - X_e) + T^e s], X_e the corners at rest relative to corner 0.
struct CorotatedForcesInput {
  const double* x = nullptr;                 ///< 3 per vertex: the displacement (plus a damping term), mm
  const std::int32_t* corners = nullptr;     ///< 8 vertex ids per cell
  const double* rotation = nullptr;          ///< 9 per cell: R column-major, R(i, j) at 3 j + i
  const std::uint8_t* material = nullptr;    ///< per cell: its material slot
  const double* stiffness_modes = nullptr;   ///< per material slot: K^e's 9 blocks in modes (corner_mode_form)
  double cell_size_mm = 1.0;
  /// T^e by component: [8 (3 k + i) + a] = T^e(3 a + i, k), 144 values (mm^2).
  const double* stress_divergence = nullptr;
  const double* stress = nullptr;            ///< 6 per cell (Voigt, kPa), or null (no stress)
  double* per_cell = nullptr;                ///< out: 24 per cell, its corners' 8 x, 8 y, 8 z (mN)
};

/// The kernel below was compiled for AVX-512 (x86-64 with GCC or Clang); false elsewhere.
extern const bool kAvx512CellPassCompiled;

/// The kernel was compiled and the CPU runs AVX-512 F and DQ (checked once).
bool avx512_cell_pass_supported();

/// per_cell of cells [begin, end): R [K + s (x) I_3] R^T x_e, as the portable pass computes it
/// (to rounding: the modes are summed in another order).
void corotated_cells_avx512(const CorotatedCellsInput& in, std::size_t begin, std::size_t end);
/// The same in double, one cell per 8-double register (the CG's residual products).
void corotated_cells_avx512(const CorotatedCellsInputDouble& in, std::size_t begin, std::size_t end);
/// per_cell of cells [begin, end): the cells' corotated elastic and stress forces, one cell per
/// 8-double register, in corner modes.
void corotated_forces_avx512(const CorotatedForcesInput& in, std::size_t begin, std::size_t end);

}  // namespace cleave
