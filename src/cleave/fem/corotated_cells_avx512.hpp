#pragma once
// The cell passes of the corotated system's product (fem/corotated_system_operator.hpp) in
// AVX-512. Float: two cells per 16-lane register, lanes 0-7 the first cell's 8 corners, lanes 8-15
// the second's; double: one cell per 8-lane register. The portable pass (AVX2 through Eigen, one
// cell per 8-float register) does the same arithmetic; on a core with two 512-bit FMA pipes this
// one does it in half the instructions.
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
struct CorotatedCellsInput {
  const float* x = nullptr;                  ///< 3 per vertex (fixed dofs already zero)
  const std::int32_t* corners = nullptr;     ///< 8 vertex ids per cell
  const float* rotation = nullptr;           ///< 9 per cell: R column-major, R(i, j) at 3 j + i
  const std::uint8_t* material = nullptr;    ///< per cell: its material slot
  /// Per material slot: 9 blocks [3 i + j] of 8 x 8 floats, column-major ((a, b) at a + 8 b):
  /// c_stiff K(3 a + i, 3 b + j).
  const float* stiffness = nullptr;
  const float* stress_stiffness = nullptr;   ///< 64 per cell, column-major, or null (no tension)
  float* per_cell = nullptr;                 ///< out: 24 per cell, its corners' 8 x, 8 y, 8 z
};

/// The double cell pass's arrays: as CorotatedCellsInput in double, with the tension instead of
/// the formed stress stiffness (the double product forms it per cell, as the portable pass does).
struct CorotatedCellsInputDouble {
  const double* x = nullptr;                 ///< 3 per vertex (fixed dofs already zero)
  const std::int32_t* corners = nullptr;     ///< 8 vertex ids per cell
  const double* rotation = nullptr;          ///< 9 per cell: R column-major, R(i, j) at 3 j + i
  const std::uint8_t* material = nullptr;    ///< per cell: its material slot
  const double* stiffness = nullptr;         ///< per material slot: 9 blocks of 8 x 8, as in float
  const double* tension = nullptr;           ///< 6 per cell (c_stress t), or null (no tension)
  const double* stress_basis = nullptr;      ///< the six G_k, 8 x 8 column-major each
  double* per_cell = nullptr;                ///< out: 24 per cell, its corners' 8 x, 8 y, 8 z
};

/// The kernel below was compiled for AVX-512 (x86-64 with GCC or Clang); false elsewhere.
extern const bool kAvx512CellPassCompiled;

/// The kernel was compiled and the CPU runs AVX-512 F and DQ (checked once).
bool avx512_cell_pass_supported();

/// per_cell of cells [begin, end): R [K + s (x) I_3] R^T x_e, as the portable pass computes it.
void corotated_cells_avx512(const CorotatedCellsInput& in, std::size_t begin, std::size_t end);
/// The same in double, one cell per 8-double register (the CG's residual products).
void corotated_cells_avx512(const CorotatedCellsInputDouble& in, std::size_t begin, std::size_t end);

}  // namespace cleave
