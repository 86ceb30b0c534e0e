#include "cleave/fem/material.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {

void validate_material(const Material& m, const std::string& field) {
  if (!std::isfinite(m.youngs_modulus_kPa) || m.youngs_modulus_kPa <= 0)
    throw InputError(fmt::format("{}.E_kPa is {}; expected a positive Young's modulus in kPa", field, m.youngs_modulus_kPa));
  if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio <= -1.0 || m.poisson_ratio >= 0.5)
    throw InputError(fmt::format("{}.nu is {}; expected a Poisson ratio in (-1, 0.5)", field, m.poisson_ratio));
  if (!std::isfinite(m.density_kg_per_m3) || m.density_kg_per_m3 <= 0)
    throw InputError(fmt::format("{}.density_kg_per_m3 is {}; expected a positive density", field, m.density_kg_per_m3));
}

}  // namespace cleave
