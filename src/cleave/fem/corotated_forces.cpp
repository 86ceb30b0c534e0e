#include "cleave/fem/corotated_forces.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_cells_avx512.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/cube_corner_modes.hpp"

namespace cleave {
namespace {

constexpr CellId kCellsPerTask = 512;

}  // namespace

void CorotatedForcePass::set_topology(const LinkedVolume& volume, const ElementTable& table) {
  volume_ = &volume;
  table_ = &table;
  material_ = material_slot_per_cell(table, volume);
  stiffness_modes_.clear();
  modes_available_ = avx512_cell_pass_supported();
  for (const ElementMatrices& material : table.per_material) {
    const auto form = corner_mode_form(material.stiffness);
    if (!form) {
      modes_available_ = false;
      break;
    }
    for (const Vec8& block : *form) stiffness_modes_.insert(stiffness_modes_.end(), block.data(), block.data() + 8);
  }
  for (int k = 0; k < 6; ++k)
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < kCornerCount; ++a)
        stress_divergence_[static_cast<std::size_t>(8 * (3 * k + i) + a)] = table.stress_divergence(3 * a + i, k);
  mode_pass_ = modes_available_;
}

void CorotatedForcePass::set_mode_pass(bool on) {
  if (on && !modes_available_)
    throw InputError("corotated forces: the mode pass needs AVX-512 F and DQ and element matrices of the corner-mode form");
  mode_pass_ = on;
}

void CorotatedForcePass::check_sizes(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm) const {
  if (volume_ == nullptr) throw InputError("corotated forces: set_topology must come before a pass");
  const std::size_t cells = material_.size();
  if (rotations.size() != cells || (!stress_kPa.empty() && stress_kPa.size() != cells) ||
      x_mm.size() != 3 * static_cast<Eigen::Index>(volume_->vertex_count()))
    throw InputError(fmt::format("corotated forces: {} rotations, {} stresses and {} displacement values; expected {} cells "
                                 "(stresses: or none) and {} values",
                                 rotations.size(), stress_kPa.size(), x_mm.size(), cells, 3 * volume_->vertex_count()));
}

void CorotatedForcePass::per_cell(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm,
                                  std::vector<double>& out) const {
  check_sizes(rotations, stress_kPa, x_mm);
  const std::size_t cells = material_.size();
  out.resize(24 * cells);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, kCellsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
    cells_in_range(rotations, stress_kPa, x_mm, r.begin(), r.end(), out);
  });
}

void CorotatedForcePass::per_cell(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm,
                                  std::span<const CellRange> cell_ranges, std::vector<double>& out) const {
  check_sizes(rotations, stress_kPa, x_mm);
  const std::size_t cells = material_.size();
  if (out.size() != 24 * cells)
    throw InputError(fmt::format("corotated forces over cell ranges: {} values for {} cells; expected 24 per cell", out.size(), cells));
  require_ranges_within(cell_ranges, cells, "corotated forces over cell ranges");
  for_each_cell_range(cell_ranges, [&](std::size_t begin, std::size_t end) { cells_in_range(rotations, stress_kPa, x_mm, begin, end, out); });
}

void CorotatedForcePass::cells_in_range(std::span<const Mat3> rotations, std::span<const Vec6> stress_kPa, const Vector& x_mm,
                                        std::size_t begin, std::size_t end, std::vector<double>& out) const {
  if (begin >= end) return;
  if (mode_pass_) {
    static_assert(sizeof(Mat3) == 9 * sizeof(double) && sizeof(Vec6) == 6 * sizeof(double));
    CorotatedForcesInput in;
    in.x = x_mm.data();
    in.corners = volume_->cell_vertices(0).data();
    in.rotation = rotations.front().data();
    in.material = material_.data();
    in.stiffness_modes = stiffness_modes_.data();
    in.cell_size_mm = table_->cell_size_mm;
    in.stress_divergence = stress_divergence_.data();
    in.stress = stress_kPa.empty() ? nullptr : stress_kPa.front().data();
    in.per_cell = out.data();
    corotated_forces_avx512(in, begin, end);
    return;
  }
  const double h = table_->cell_size_mm;
  for (auto c = static_cast<CellId>(begin); c != static_cast<CellId>(end); ++c) {
    const auto ci = static_cast<std::size_t>(c);
    const Mat3& rot = rotations[ci];
    const Vec24 d = corotated_displacement(cell_displacement(*volume_, c, x_mm), rot, h);
    // lazyProduct: unrolled in registers, not a GEMV call per cell.
    Vec24 local = table_->per_material[material_[ci]].stiffness.lazyProduct(d);
    if (!stress_kPa.empty()) local += table_->stress_divergence.lazyProduct(stress_kPa[ci]);
    double* to = out.data() + 24 * ci;
    for (int a = 0; a < kCornerCount; ++a) {
      const Vec3 world = rot * local.segment<3>(3 * a);
      for (int i = 0; i < 3; ++i) to[8 * i + a] = world[i];
    }
  }
}

}  // namespace cleave
