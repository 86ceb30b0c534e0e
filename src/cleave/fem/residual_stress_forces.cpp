#include "cleave/fem/residual_stress_forces.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/hex8_element.hpp"

namespace cleave {

Vector residual_stress_forces(const LinkedVolume& volume, std::span<const Vec6> stress_kPa) {
  if (stress_kPa.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("residual stress holds {} cell tensors; expected one per cell ({})", stress_kPa.size(),
                                 volume.cell_count()));
  const Mat24x6 te = hex8_stress_divergence(volume.grid().cell_size_mm);
  Vector f = Vector::Zero(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec24 fe = te * stress_kPa[static_cast<std::size_t>(c)];
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a) f.segment<3>(3 * corners[static_cast<std::size_t>(a)]) += fe.segment<3>(3 * a);
  }
  return f;
}

std::vector<Vec6> stress_divergence_transpose(const LinkedVolume& volume, const Vector& vertex_values) {
  if (vertex_values.size() != 3 * static_cast<Eigen::Index>(volume.vertex_count()))
    throw InputError(fmt::format("vertex vector holds {} values; expected 3 per vertex ({})", vertex_values.size(),
                                 3 * static_cast<Eigen::Index>(volume.vertex_count())));
  const Mat24x6 te = hex8_stress_divergence(volume.grid().cell_size_mm);
  std::vector<Vec6> out(static_cast<std::size_t>(volume.cell_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    Vec24 fe;
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a) fe.segment<3>(3 * a) = vertex_values.segment<3>(3 * corners[static_cast<std::size_t>(a)]);
    out[static_cast<std::size_t>(c)] = te.transpose() * fe;
  }
  return out;
}

}  // namespace cleave
