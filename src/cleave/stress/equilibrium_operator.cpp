#include "cleave/stress/equilibrium_operator.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/solve/sparse_multiply.hpp"

namespace cleave {
namespace {

/// Power-iteration steps for ||T||_2: the estimate is a lower bound that is within a few percent
/// after this many steps on grid operators (it only scales the reported residual).
constexpr int kPowerSteps = 30;

}  // namespace

SparseMatrix stress_divergence_matrix(const LinkedVolume& volume) {
  const Mat24x6 te = hex8_stress_divergence(volume.grid().cell_size_mm);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(volume.cell_count()) * 24 * 6);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a)
      for (int d = 0; d < 3; ++d)
        for (int k = 0; k < 6; ++k) {
          const double value = te(3 * a + d, k);
          if (value != 0.0) entries.emplace_back(3 * corners[static_cast<std::size_t>(a)] + d, 6 * c + k, value);
        }
  }
  SparseMatrix t(3 * static_cast<Eigen::Index>(volume.vertex_count()), 6 * static_cast<Eigen::Index>(volume.cell_count()));
  t.setFromTriplets(entries.begin(), entries.end());
  return t;
}

SparseMatrix eigenvalue_divergence_matrix(const LinkedVolume& volume, std::span<const DirectionFrame> frames) {
  if (frames.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("got {} direction frames; expected one per cell ({})", frames.size(), volume.cell_count()));
  const Mat24x6 te = hex8_stress_divergence(volume.grid().cell_size_mm);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(volume.cell_count()) * 24 * 3);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const DirectionFrame& f = frames[static_cast<std::size_t>(c)];
    Eigen::Matrix<double, 6, 3> ds;
    ds.col(0) = to_voigt(f.langer * f.langer.transpose());
    ds.col(1) = to_voigt(f.cross * f.cross.transpose());
    ds.col(2) = to_voigt(f.normal * f.normal.transpose());
    const Eigen::Matrix<double, 24, 3> ge = te * ds;
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a)
      for (int d = 0; d < 3; ++d)
        for (int i = 0; i < 3; ++i) entries.emplace_back(3 * corners[static_cast<std::size_t>(a)] + d, 3 * c + i, ge(3 * a + d, i));
  }
  SparseMatrix g(3 * static_cast<Eigen::Index>(volume.vertex_count()), 3 * static_cast<Eigen::Index>(volume.cell_count()));
  g.setFromTriplets(entries.begin(), entries.end());
  return g;
}

std::vector<std::uint8_t> held_dof_flags(VertexId vertex_count, std::span<const VertexId> held_vertices) {
  std::vector<std::uint8_t> held(3 * static_cast<std::size_t>(vertex_count), 0);
  for (const VertexId v : held_vertices) {
    if (v < 0 || v >= vertex_count)
      throw InputError(fmt::format("held vertex {} does not exist; expected 0 to {}", v, vertex_count - 1));
    for (int a = 0; a < 3; ++a) held[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(a)] = 1;
  }
  return held;
}

void drop_held_vertex_rows(SparseMatrix& t, std::span<const VertexId> held_vertices) {
  if (held_vertices.empty()) return;
  const std::vector<std::uint8_t> held = held_dof_flags(static_cast<VertexId>(t.rows() / 3), held_vertices);
  t.prune([&](Eigen::Index row, Eigen::Index, double) { return held[static_cast<std::size_t>(row)] == 0; });
}

EquilibriumNorm equilibrium_norm(const SparseMatrix& t) {
  Vector x = Vector::Ones(t.cols());
  // A deterministic, non-smooth start so that the oscillating top singular vector is reached.
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::cos(0.7 * static_cast<double>(i)) + 0.1;
  double sigma_squared = 0;
  for (int step = 0; step < kPowerSteps; ++step) {
    const double norm = x.norm();
    if (norm == 0.0) break;
    x /= norm;
    const Vector tx = t * x;
    x = t.transpose() * tx;
    sigma_squared = x.norm();
  }
  return {std::sqrt(sigma_squared)};
}

Vector flatten_stress(std::span<const Vec6> stress_kPa) {
  Vector flat(6 * static_cast<Eigen::Index>(stress_kPa.size()));
  for (std::size_t c = 0; c < stress_kPa.size(); ++c) flat.segment<6>(6 * static_cast<Eigen::Index>(c)) = stress_kPa[c];
  return flat;
}

std::vector<Vec6> unflatten_stress(const Vector& flat) {
  std::vector<Vec6> stress(static_cast<std::size_t>(flat.size() / 6));
  for (std::size_t c = 0; c < stress.size(); ++c) stress[c] = flat.segment<6>(6 * static_cast<Eigen::Index>(c));
  return stress;
}

double relative_equilibrium_residual(double force_norm_mN, const EquilibriumNorm& norm, std::span<const Vec6> stress_kPa) {
  double squared = 0.0;
  for (const Vec6& s : stress_kPa) squared += s.squaredNorm();
  const double denominator = norm.spectral_norm_mm2 * std::sqrt(squared);
  return denominator == 0.0 ? 0.0 : force_norm_mN / denominator;
}

double relative_equilibrium_residual(const SparseMatrix& t, const EquilibriumNorm& norm, std::span<const Vec6> stress_kPa) {
  if (static_cast<Eigen::Index>(6 * stress_kPa.size()) != t.cols())
    throw InputError(fmt::format("stress holds {} cell tensors; expected {}", stress_kPa.size(), t.cols() / 6));
  Vector ts;
  multiply(t, flatten_stress(stress_kPa), ts);  // on all cores (Eigen's sparse product runs on one)
  return relative_equilibrium_residual(ts.norm(), norm, stress_kPa);
}

}  // namespace cleave
