#include "cleave/fem/cell_stress.hpp"

#include <Eigen/LU>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/element_table.hpp"

namespace cleave {

std::vector<Vec6> total_cell_stress_kPa(const TissueModel& model, std::span<const Vec6> residual, std::span<const Vec3> displacement) {
  const LinkedVolume& volume = model.volume;
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  if (!residual.empty() && residual.size() != cells)
    throw InputError(fmt::format("residual stress holds {} cell tensors; expected one per cell ({})", residual.size(), cells));
  if (!displacement.empty() && displacement.size() != static_cast<std::size_t>(volume.vertex_count()))
    throw InputError(fmt::format("displacement holds {} vectors; expected one per vertex ({})", displacement.size(),
                                 volume.vertex_count()));
  const ElementTable table = make_element_table(model);
  const double h = volume.grid().cell_size_mm;
  std::vector<Vec6> out(cells, Vec6::Zero());
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const auto ci = static_cast<std::size_t>(c);
    const Vec6 res = residual.empty() ? Vec6::Zero() : residual[ci];
    if (displacement.empty()) {
      out[ci] = res;
      continue;
    }
    Mat3 f = Mat3::Identity();
    {
      Vec24 ue;
      for (int a = 0; a < kCornerCount; ++a) ue.segment<3>(3 * a) = displacement[static_cast<std::size_t>(volume.corner_vertex(c, a))];
      f = hex8_center_deformation_gradient(ue, h);
    }
    const Mat3 r = rotation_from_deformation_gradient(f);
    const Vec6 local = res + table.of_label(volume.cell_label(c)).elasticity_kPa * corotated_strain(f, r);
    out[ci] = to_voigt(r * from_voigt(local) * r.transpose());
  }
  return out;
}

}  // namespace cleave
