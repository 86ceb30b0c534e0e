#pragma once
// cleave's unit convention, stated once.
//
// Inside the library every quantity uses one consistent system:
//   length  mm      (positions, displacements, cell sizes)
//   stress  kPa     (Young's modulus, residual stress, eigenvalues)
//   time    s
//   mass    kg      (density in kg/mm^3; 1000 kg/m^3 = 1e-6 kg/mm^3)
//   force   mN      (kPa * mm^2 = 1e-3 N = kg * mm / s^2, so K u = f and M a = f agree)
// Names carry the unit where a value crosses a boundary (`cell_size_mm`, `youngs_modulus_kPa`).
// Output files state their units: VTU stresses are written in Pa, displacements in mm.

namespace cleave::units {

inline constexpr double kPa_per_Pa = 1e-3;
inline constexpr double Pa_per_kPa = 1e3;
inline constexpr double kg_per_mm3_per_kg_per_m3 = 1e-9;

/// The largest stress magnitude a case file may give (kPa): 1 TPa, beyond any material (bone ~2e7
/// kPa). Larger finite values overflow the forces (stress x area) and the energies in double.
inline constexpr double kLargestStress_kPa = 1e9;

/// Density given in kg/m^3 (the usual tissue figure, ~1000) converted to kg/mm^3.
constexpr double density_kg_per_mm3(double density_kg_per_m3) { return density_kg_per_m3 * kg_per_mm3_per_kg_per_m3; }

}  // namespace cleave::units
