#pragma once
// Linear isotropic material of one tissue label.
#include <string>

namespace cleave {

/// Defaults follow the paper (section 7): E = 80 kPa, nu = 0.4 (abdominal wall), 1000 kg/m^3.
struct Material {
  std::string name = "tissue";
  double youngs_modulus_kPa = 80.0;
  double poisson_ratio = 0.4;
  double density_kg_per_m3 = 1000.0;
};

/// Throws InputError naming `field` (e.g. "materials[1].E_kPa") when E <= 0, nu outside
/// (-1, 0.5), the density is not positive, or any value is not finite.
void validate_material(const Material& material, const std::string& field);

}  // namespace cleave
