#include "cleave/stress/centre_point_stiffness.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/grid/vertex_corner_slots.hpp"

namespace cleave {
namespace {

constexpr std::size_t kCellsPerTask = 1024;
constexpr VertexId kVerticesPerTask = 2048;

}  // namespace

CentrePointStiffness::CentrePointStiffness(const LinkedVolume& volume, const ElementTable& table,
                                           std::span<const std::uint8_t> held_dof)
    : volume_(volume), held_(held_dof.begin(), held_dof.end()) {
  const auto dofs = 3 * static_cast<std::size_t>(volume.vertex_count());
  if (held_.size() != dofs)
    throw InputError(fmt::format("centre-point stiffness: {} held-dof flags; expected one per dof ({})", held_.size(), dofs));
  const double h = volume.grid().cell_size_mm;
  cell_volume_mm3_ = h * h * h;
  const Mat6x24 bc = hex8_strain_matrix(Vec3::Constant(0.5), h);
  for (int a = 0; a < kCornerCount; ++a) {
    gradient_x_[a] = bc(0, 3 * a);
    gradient_y_[a] = bc(1, 3 * a + 1);
    gradient_z_[a] = bc(2, 3 * a + 2);
  }
  for (const ElementMatrices& m : table.per_material) elasticity_kPa_.push_back(m.elasticity_kPa);
  material_.resize(static_cast<std::size_t>(volume.cell_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const int slot = table.slot_of_label[volume.cell_label(c)];
    if (slot < 0) throw InputError(fmt::format("centre-point stiffness: label {} of cell {} has no material", volume.cell_label(c), c));
    material_[static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(slot);
  }
  any_held_ = std::any_of(held_.begin(), held_.end(), [](std::uint8_t flag) { return flag != 0; });
  VertexCornerSlots slots = vertex_corner_slots(volume, 24);  // per_cell_: 24 values per cell
  vertex_start_ = std::move(slots.start);
  vertex_slot_ = std::move(slots.slot);
}

SparseMatrix CentrePointStiffness::assembled() const {
  const Mat6x24 bc = hex8_strain_matrix(Vec3::Constant(0.5), volume_.grid().cell_size_mm);
  std::vector<Mat24> per_material;
  for (const Mat6& d : elasticity_kPa_) per_material.push_back(cell_volume_mm3_ * bc.transpose() * d * bc);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(volume_.cell_count()) * 24 * 24);
  for (CellId c = 0; c < volume_.cell_count(); ++c) {
    const Mat24& ke = per_material[material_[static_cast<std::size_t>(c)]];
    const auto& corners = volume_.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a)
      for (int b = 0; b < kCornerCount; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const VertexId row = 3 * corners[static_cast<std::size_t>(a)] + i, col = 3 * corners[static_cast<std::size_t>(b)] + j;
            if (held_[static_cast<std::size_t>(row)] || held_[static_cast<std::size_t>(col)]) continue;
            entries.emplace_back(row, col, ke(3 * a + i, 3 * b + j));
          }
  }
  for (std::size_t d = 0; d < held_.size(); ++d)
    if (held_[d]) entries.emplace_back(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d), 1.0);
  SparseMatrix out(rows(), rows());
  out.setFromTriplets(entries.begin(), entries.end());
  out.makeCompressed();
  return out;
}

void CentrePointStiffness::check_size(const Vector& x) const {
  if (x.size() != rows())
    throw InputError(fmt::format("centre-point stiffness: vector has {} entries; expected {}", x.size(), rows()));
}

Vec6 CentrePointStiffness::cell_stress(CellId c, const Vector& x) const {
  Corners ux, uy, uz;
  const auto& corners = volume_.cell_vertices(c);
  for (int a = 0; a < kCornerCount; ++a) {
    const double* xa = x.data() + 3 * static_cast<Eigen::Index>(corners[static_cast<std::size_t>(a)]);
    ux[a] = xa[0];
    uy[a] = xa[1];
    uz[a] = xa[2];
  }
  Vec6 strain;  // Voigt, engineering shear (fem/hex8_element.hpp)
  strain << gradient_x_.dot(ux), gradient_y_.dot(uy), gradient_z_.dot(uz), gradient_y_.dot(ux) + gradient_x_.dot(uy),
      gradient_z_.dot(ux) + gradient_x_.dot(uz), gradient_z_.dot(uy) + gradient_y_.dot(uz);
  return elasticity_kPa_[material_[static_cast<std::size_t>(c)]] * strain;
}

void CentrePointStiffness::multiply(const Vector& x_in, Vector& y) const {
  check_size(x_in);
  const Vector* x = &x_in;
  if (any_held_) {  // held columns are zero
    masked_ = x_in;
    for (std::size_t d = 0; d < held_.size(); ++d)
      if (held_[d]) masked_[static_cast<Eigen::Index>(d)] = 0.0;
    x = &masked_;
  }
  const auto cells = static_cast<std::size_t>(volume_.cell_count());
  per_cell_.resize(24 * cells);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, kCellsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) {
      const Vec6 s = cell_volume_mm3_ * cell_stress(static_cast<CellId>(c), *x);
      double* out = per_cell_.data() + 24 * c;  // Bc^T s by component
      Eigen::Map<Corners> fx(out), fy(out + 8), fz(out + 16);
      fx = s[0] * gradient_x_ + s[3] * gradient_y_ + s[4] * gradient_z_;
      fy = s[3] * gradient_x_ + s[1] * gradient_y_ + s[5] * gradient_z_;
      fz = s[4] * gradient_x_ + s[5] * gradient_y_ + s[2] * gradient_z_;
    }
  });
  y.resize(x_in.size());
  const auto vertices = static_cast<VertexId>(vertex_start_.size() - 1);
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v < r.end(); ++v) {
      Vec3 sum = Vec3::Zero();
      for (std::int32_t s = vertex_start_[static_cast<std::size_t>(v)]; s < vertex_start_[static_cast<std::size_t>(v) + 1]; ++s) {
        const double* corner = per_cell_.data() + vertex_slot_[static_cast<std::size_t>(s)];
        sum += Vec3(corner[0], corner[8], corner[16]);
      }
      const auto i = 3 * static_cast<Eigen::Index>(v);
      if (any_held_)
        for (int axis = 0; axis < 3; ++axis)
          if (held_[static_cast<std::size_t>(i + axis)]) sum[axis] = x_in[i + axis];  // identity row
      y.segment<3>(i) = sum;
    }
  });
}

void CentrePointStiffness::residual(const Vector& b, const Vector& x, Vector& r) const {
  check_size(b);
  multiply(x, r);
  r = b - r;
}

void CentrePointStiffness::add_stress(const Vector& u, std::span<Vec6> stress_kPa) const {
  check_size(u);
  if (stress_kPa.size() != material_.size())
    throw InputError(fmt::format("centre-point stiffness: {} cell stresses; expected one per cell ({})", stress_kPa.size(),
                                 material_.size()));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, material_.size(), kCellsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) stress_kPa[c] += cell_stress(static_cast<CellId>(c), u);
  });
}

}  // namespace cleave
