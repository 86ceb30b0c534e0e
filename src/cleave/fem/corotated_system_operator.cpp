#include "cleave/fem/corotated_system_operator.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <type_traits>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_cells_avx512.hpp"
#include "cleave/fem/cube_corner_modes.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "cleave/grid/vertex_corner_slots.hpp"
#include "cleave/solve/block_jacobi.hpp"

namespace cleave {
namespace {

constexpr CellId kCellsPerTask = 512;
constexpr VertexId kVerticesPerTask = 1024;
constexpr Eigen::Index kDofsPerTask = Eigen::Index{1} << 14;

/// A cell's stress stiffness sum_k t_k G_k (8 x 8, the coefficient of I_3 per corner pair).
template <typename Scalar>
Eigen::Matrix<Scalar, 8, 8> stress_stiffness_of(const Eigen::Matrix<Scalar, 6, 1>& t,
                                                const std::array<Eigen::Matrix<Scalar, 8, 8>, 6>& basis) {
  Eigen::Matrix<Scalar, 8, 8> s = t[0] * basis[0];
  for (int q = 1; q < 6; ++q) s += t[q] * basis[static_cast<std::size_t>(q)];
  return s;
}

/// R s for the corner's outward signs s (+-1 per axis): the columns of R added or subtracted.
Vec3 corner_sign_sum(const Mat3& rotation, int corner) {
  const Vec3i o = corner_offset(corner);
  Vec3 sum = o[0] != 0 ? Vec3(rotation.col(0)) : Vec3(-rotation.col(0));
  sum += o[1] != 0 ? Vec3(rotation.col(1)) : Vec3(-rotation.col(1));
  sum += o[2] != 0 ? Vec3(rotation.col(2)) : Vec3(-rotation.col(2));
  return sum;
}

}  // namespace

bool avx512_cell_pass_supported() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool supported = kAvx512CellPassCompiled && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  return supported;
#else
  return false;
#endif
}

void CorotatedSystemOperator::set_topology(const LinkedVolume& volume, const ElementTable& table) {
  volume_ = &volume;
  table_ = &table;
  material_ = material_slot_per_cell(table, volume);
  corner_slots_ = vertex_corner_slots(volume, 24);  // per_cell: 24 values per cell
  rotations_ = {};
  fixed_seen_.clear();  // set_state lists the fixed dofs and held cells of the new topology
  // The element matrices in corner modes, for the AVX-512 passes (none: the portable pass).
  stiffness_modes_.clear();
  stress_modes_.reset();
  if (const auto stress = corner_mode_form(table.stress_stiffness)) {
    for (const ElementMatrices& material : table.per_material) {
      const auto form = corner_mode_form(material.stiffness);
      if (!form) {
        stiffness_modes_.clear();
        return;
      }
      stiffness_modes_.push_back(*form);
    }
    stress_modes_ = *stress;
  }
}

template <typename Scalar>
void CorotatedSystemOperator::set_mode_coefficients(Precision<Scalar>& p, double c_stiff) const {
  p.stiffness_modes.resize(72 * stiffness_modes_.size());
  for (std::size_t m = 0; m < stiffness_modes_.size(); ++m)
    for (std::size_t b = 0; b < 9; ++b)
      for (Eigen::Index mode = 0; mode < 8; ++mode)
        p.stiffness_modes[72 * m + 8 * b + static_cast<std::size_t>(mode)] = static_cast<Scalar>(c_stiff * stiffness_modes_[m][b][mode]);
  p.stress_modes.assign(stress_modes_ ? 48 : 0, Scalar{0});
  if (stress_modes_)
    for (std::size_t q = 0; q < 6; ++q)
      for (Eigen::Index mode = 0; mode < 8; ++mode) p.stress_modes[8 * q + static_cast<std::size_t>(mode)] = static_cast<Scalar>((*stress_modes_)[q][mode]);
}

bool CorotatedSystemOperator::mode_cell_pass() const {
  return wide_cell_pass_ && stress_modes_.has_value() && !stiffness_modes_.empty();
}

void CorotatedSystemOperator::form_stress_stiffness() const {
  const std::size_t cells = material_.size();
  if (!with_tension_ || single_.stress_stiffness.size() == cells) return;
  single_.stress_stiffness.resize(cells);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, kCellsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c)
      single_.stress_stiffness[c] = stress_stiffness_of(twin_.tension[c], twin_.stress_basis).cast<float>();
  });
}

void CorotatedSystemOperator::set_state(std::span<const Mat3> rotations, std::span<const Vec6> tension_kPa, double c_stiff,
                                        double c_stress, double c_mass, const Vector& mass_kg, const std::vector<std::uint8_t>& fixed) {
  if (volume_ == nullptr) throw InputError("corotated system: set_topology must come before set_state");
  const std::size_t cells = material_.size();
  const auto dofs = static_cast<std::size_t>(rows());
  if (rotations.size() != cells || (!tension_kPa.empty() && tension_kPa.size() != cells) ||
      static_cast<std::size_t>(mass_kg.size()) != dofs || fixed.size() != dofs)
    throw InputError(fmt::format("corotated system: {} rotations, {} tensions, {} masses and {} fixed flags; expected {} cells "
                                 "(tensions: or none) and {} dofs",
                                 rotations.size(), tension_kPa.size(), mass_kg.size(), fixed.size(), cells, dofs));
  rotations_ = rotations;
  with_tension_ = !tension_kPa.empty();
  fixed_ = &fixed;
  if (fixed != fixed_seen_) {  // a step keeps its fixed dofs: listed once
    fixed_seen_ = fixed;
    fixed_rows_.clear();
    for (std::size_t i = 0; i < dofs; ++i)
      if (fixed[i] != 0) fixed_rows_.push_back(static_cast<Eigen::Index>(i));
    list_held_cells();
  }
  c_mass_ = c_mass;
  mass_kg_ = &mass_kg;
  const std::size_t materials = table_->per_material.size();
  twin_.stiffness.resize(materials);
  single_.stiffness_by_component.resize(materials);
  twin_.stiffness_by_component.resize(materials);
  for (std::size_t m = 0; m < materials; ++m) {
    twin_.stiffness[m] = c_stiff * table_->per_material[m].stiffness;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int a = 0; a < kCornerCount; ++a)
          for (int b = 0; b < kCornerCount; ++b) {
            const double k = twin_.stiffness[m](3 * a + i, 3 * b + j);
            twin_.stiffness_by_component[m][static_cast<std::size_t>(3 * i + j)](a, b) = k;
            single_.stiffness_by_component[m][static_cast<std::size_t>(3 * i + j)](a, b) = static_cast<float>(k);
          }
  }
  split_corner_diagonals();
  set_mode_coefficients(single_, c_stiff);
  set_mode_coefficients(twin_, c_stiff);
  for (std::size_t k = 0; k < 6; ++k) {
    for (int a = 0; a < kCornerCount; ++a)
      stress_diagonal_basis_[static_cast<std::size_t>(a)][static_cast<Eigen::Index>(k)] = table_->stress_stiffness[k](a, a);
    twin_.stress_basis[k] = table_->stress_stiffness[k];
    single_.stress_basis[k] = table_->stress_stiffness[k].cast<float>();
  }
  single_.rotation.resize(cells);
  twin_.tension.resize(with_tension_ ? cells : 0);
  single_.tension.resize(with_tension_ ? cells : 0);
  single_.stress_stiffness.clear();  // formed by the portable float pass when it runs
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, kCellsPerTask), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) {
      single_.rotation[c] = rotations[c].cast<float>();
      if (with_tension_) {
        twin_.tension[c] = c_stress * tension_kPa[c];
        single_.tension[c] = twin_.tension[c].cast<float>();
      }
    }
  });
  if (!mode_cell_pass()) form_stress_stiffness();
  twin_.mass_term = c_mass * mass_kg;
  for (std::size_t i = 0; i < dofs; ++i)
    if (fixed[i] != 0) twin_.mass_term[static_cast<Eigen::Index>(i)] = 0;
  single_.mass_term = twin_.mass_term.cast<float>();
}

void CorotatedSystemOperator::list_held_cells() {
  const auto vertices = static_cast<std::size_t>(rows() / 3);
  vertex_held_.assign(vertices, 0);
  for (std::size_t v = 0; v < vertices; ++v)
    vertex_held_[v] = fixed_seen_[3 * v] != 0 && fixed_seen_[3 * v + 1] != 0 && fixed_seen_[3 * v + 2] != 0 ? 1 : 0;
  cell_ranges_.clear();
  const std::size_t cells = material_.size();
  const auto computed = [&](std::size_t c) {
    const auto& corners = volume_->cell_vertices(static_cast<CellId>(c));
    return std::any_of(corners.begin(), corners.end(), [&](VertexId v) { return vertex_held_[static_cast<std::size_t>(v)] == 0; });
  };
  for (std::size_t c = 0; c < cells; ++c) {
    if (!computed(c)) continue;
    const std::size_t begin = c;
    while (c + 1 < cells && c + 1 - begin < static_cast<std::size_t>(kCellsPerTask) && computed(c + 1)) ++c;
    cell_ranges_.emplace_back(begin, c + 1);
  }
}

std::size_t CorotatedSystemOperator::computed_cells() const {
  std::size_t count = 0;
  for (const auto& [begin, end] : cell_ranges_) count += end - begin;
  return count;
}

template <>
const Eigen::Matrix<float, 3, 3>& CorotatedSystemOperator::rotation_of<float>(const Precision<float>& p, std::size_t cell) const {
  return p.rotation[cell];
}
template <>
const Mat3& CorotatedSystemOperator::rotation_of<double>(const Precision<double>&, std::size_t cell) const {
  return rotations_[cell];
}

template <typename Scalar, typename Finish>
void CorotatedSystemOperator::apply(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x_in,
                                    const Finish& finish) const {
  using Mat3S = Eigen::Matrix<Scalar, 3, 3>;
  if (rotations_.empty() && !material_.empty()) throw InputError("corotated system: set_state must come before a product");
  if (x_in.size() != rows())
    throw InputError(fmt::format("corotated system: vector has {} entries; expected {}", x_in.size(), rows()));
  const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>* x = &x_in;
  if (!fixed_rows_.empty()) {  // fixed columns are zero
    p.masked.resize(x_in.size());
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, x_in.size(), kDofsPerTask), [&](const tbb::blocked_range<Eigen::Index>& r) {
      p.masked.segment(r.begin(), r.end() - r.begin()) = x_in.segment(r.begin(), r.end() - r.begin());
    });
    for (const Eigen::Index i : fixed_rows_) p.masked[i] = 0;
    x = &p.masked;
  }
  const std::size_t cells = material_.size();
  p.per_cell.resize(24 * cells);
  if constexpr (std::is_same_v<Scalar, float>) {
    if (mode_cell_pass() && cells > 0) {
      static_assert(sizeof(Eigen::Matrix3f) == 9 * sizeof(float) && sizeof(Eigen::Matrix<float, 6, 1>) == 6 * sizeof(float) &&
                    sizeof(std::array<VertexId, 8>) == 8 * sizeof(std::int32_t));
      CorotatedCellsInput in;
      in.x = x->data();
      in.corners = volume_->cell_vertices(0).data();
      in.rotation = p.rotation.front().data();
      in.material = material_.data();
      in.stiffness_modes = p.stiffness_modes.data();
      in.stress_modes = p.stress_modes.data();
      in.tension = with_tension_ ? p.tension.front().data() : nullptr;
      in.per_cell = p.per_cell.data();
      for_each_cell_range(cell_ranges_, [&](std::size_t begin, std::size_t end) { corotated_cells_avx512(in, begin, end); });
      sum_per_vertex(p, x_in, *x, finish);
      return;
    }
  } else if (mode_cell_pass() && cells > 0) {
    static_assert(sizeof(Mat3) == 9 * sizeof(double) && sizeof(Eigen::Matrix<double, 6, 1>) == 6 * sizeof(double));
    CorotatedCellsInputDouble in;
    in.x = x->data();
    in.corners = volume_->cell_vertices(0).data();
    in.rotation = rotations_.front().data();
    in.material = material_.data();
    in.stiffness_modes = p.stiffness_modes.data();
    in.stress_modes = p.stress_modes.data();
    in.tension = with_tension_ ? p.tension.front().data() : nullptr;
    in.per_cell = p.per_cell.data();
    for_each_cell_range(cell_ranges_, [&](std::size_t begin, std::size_t end) { corotated_cells_avx512(in, begin, end); });
    sum_per_vertex(p, x_in, *x, finish);
    return;
  }
  if constexpr (std::is_same_v<Scalar, float>) form_stress_stiffness();
  for_each_cell_range(cell_ranges_, [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c < last; ++c) {
      const auto& corners = volume_->cell_vertices(static_cast<CellId>(c));
      const Mat3S& rotation = rotation_of(p, c);
      // The corners' x, y, z (world), then turned into the cell's frame: d_i = sum_j R_ji x_j.
      std::array<Corners<Scalar>, 3> world;
      for (int a = 0; a < kCornerCount; ++a) {
        const Scalar* xa = x->data() + 3 * static_cast<Eigen::Index>(corners[static_cast<std::size_t>(a)]);
        for (int j = 0; j < 3; ++j) world[static_cast<std::size_t>(j)][a] = xa[j];
      }
      std::array<Corners<Scalar>, 3> d;
      for (int i = 0; i < 3; ++i)
        d[static_cast<std::size_t>(i)] = rotation(0, i) * world[0] + rotation(1, i) * world[1] + rotation(2, i) * world[2];
      // f_i = sum_j K_ij d_j (+ s d_i: the stress stiffness couples like components only).
      const CornerBlocks<Scalar>& k = p.stiffness_by_component[material_[c]];
      std::array<Corners<Scalar>, 3> f;
      for (int i = 0; i < 3; ++i) {
        const auto row = static_cast<std::size_t>(3 * i);
        // lazyProduct: unrolled column by column (8 SIMD multiply-adds), not a GEMV call.
        f[static_cast<std::size_t>(i)].noalias() = k[row].lazyProduct(d[0]) + k[row + 1].lazyProduct(d[1]) + k[row + 2].lazyProduct(d[2]);
      }
      if constexpr (std::is_same_v<Scalar, float>) {
        if (with_tension_) {
          const Eigen::Matrix<float, 8, 8>& s = p.stress_stiffness[c];  // formed before the pass
          for (std::size_t i = 0; i < 3; ++i) f[i].noalias() += s.lazyProduct(d[i]);
        }
      } else if (with_tension_) {
        const Eigen::Matrix<Scalar, 6, 1>& t = p.tension[c];
        if (!t.isZero()) {
          const Eigen::Matrix<Scalar, 8, 8> s = stress_stiffness_of(t, p.stress_basis);
          for (std::size_t i = 0; i < 3; ++i) f[i].noalias() += s.lazyProduct(d[i]);
        }
      }
      // Back into the world: out_i = sum_j R_ij f_j.
      Scalar* out = p.per_cell.data() + 24 * c;
      for (int i = 0; i < 3; ++i)
        Eigen::Map<Corners<Scalar>>(out + 8 * i) = rotation(i, 0) * f[0] + rotation(i, 1) * f[1] + rotation(i, 2) * f[2];
    }
  });
  sum_per_vertex(p, x_in, *x, finish);
}

template <typename Scalar, typename Finish>
void CorotatedSystemOperator::sum_per_vertex(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x_in,
                                             const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x_masked, const Finish& finish) const {
  const auto vertices = static_cast<VertexId>(corner_slots_.start.size() - 1);
  const bool any_fixed = !fixed_rows_.empty();
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, vertices, kVerticesPerTask), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v < r.end(); ++v) {
      const auto i = 3 * static_cast<Eigen::Index>(v);
      if (vertex_held_[static_cast<std::size_t>(v)] != 0) {  // identity rows: no cell sum
        finish(v, Eigen::Matrix<Scalar, 3, 1>(x_in.template segment<3>(i)));
        continue;
      }
      Eigen::Matrix<Scalar, 3, 1> sum = p.mass_term.template segment<3>(i).cwiseProduct(x_masked.template segment<3>(i));
      for (std::int32_t s = corner_slots_.start[static_cast<std::size_t>(v)]; s < corner_slots_.start[static_cast<std::size_t>(v) + 1]; ++s) {
        const Scalar* slot = p.per_cell.data() + corner_slots_.slot[static_cast<std::size_t>(s)];
        sum += Eigen::Matrix<Scalar, 3, 1>(slot[0], slot[8], slot[16]);
      }
      if (any_fixed)
        for (int axis = 0; axis < 3; ++axis)
          if ((*fixed_)[static_cast<std::size_t>(i + axis)] != 0) sum[axis] = x_in[i + axis];  // identity rows
      finish(v, sum);
    }
  });
}

template <typename Scalar>
void CorotatedSystemOperator::fused_jacobi_residual(const Precision<Scalar>& p,
                                                    const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                                                    const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                                    const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                                                    Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& z) const {
  if (b.size() != rows() || static_cast<Eigen::Index>(3 * inverse_diagonal.size()) != rows())
    throw InputError(fmt::format("corotated system: right-hand side of {} entries and {} diagonal blocks; expected {} and {}", b.size(),
                                 inverse_diagonal.size(), rows(), rows() / 3));
  z.resize(rows());
  apply(p, x, [&](VertexId v, const Eigen::Matrix<Scalar, 3, 1>& ax) {
    const auto i = 3 * static_cast<Eigen::Index>(v);
    z.template segment<3>(i) = inverse_diagonal[static_cast<std::size_t>(v)] * (b.template segment<3>(i) - ax);
  });
}

template <typename Scalar>
void CorotatedSystemOperator::fused_residual(const Precision<Scalar>& p, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                             const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x,
                                             Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& r) const {
  if (b.size() != rows())
    throw InputError(fmt::format("corotated system: right-hand side of {} entries; expected {}", b.size(), rows()));
  r.resize(rows());
  apply(p, x, [&](VertexId v, const Eigen::Matrix<Scalar, 3, 1>& ax) {
    const auto i = 3 * static_cast<Eigen::Index>(v);
    r.template segment<3>(i) = b.template segment<3>(i) - ax;
  });
}

void CorotatedSystemOperator::residual(const Eigen::VectorXf& b, const Eigen::VectorXf& x, Eigen::VectorXf& r) const {
  fused_residual(single_, b, x, r);
}

void CorotatedSystemOperator::residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
  fused_residual(twin_, b, x, r);
}

template <typename Scalar>
void CorotatedSystemOperator::fused_chebyshev_step(const Precision<Scalar>& p,
                                                   const std::vector<Eigen::Matrix<Scalar, 3, 3>>& inverse_diagonal,
                                                   const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& b,
                                                   Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& x, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& d,
                                                   Scalar c_d, Scalar c_z) const {
  if (b.size() != rows() || d.size() != rows() || static_cast<Eigen::Index>(3 * inverse_diagonal.size()) != rows())
    throw InputError(fmt::format("corotated system: right-hand side of {} entries, direction of {} and {} diagonal blocks; expected "
                                 "{}, {} and {}",
                                 b.size(), d.size(), inverse_diagonal.size(), rows(), rows(), rows() / 3));
  // x is read by the cell pass (done before any vertex is finished) and, at vertex v, by v's own
  // sum (its mass term and fixed rows) before finish(v) writes it.
  apply(p, x, [&](VertexId v, const Eigen::Matrix<Scalar, 3, 1>& ax) {
    const auto i = 3 * static_cast<Eigen::Index>(v);
    const Eigen::Matrix<Scalar, 3, 1> step =
        c_d * d.template segment<3>(i) + c_z * (inverse_diagonal[static_cast<std::size_t>(v)] * (b.template segment<3>(i) - ax));
    d.template segment<3>(i) = step;
    x.template segment<3>(i) += step;
  });
}

void CorotatedSystemOperator::chebyshev_step(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b, Eigen::VectorXf& x,
                                             Eigen::VectorXf& d, float c_d, float c_z, Eigen::VectorXf&) const {
  fused_chebyshev_step(single_, inverse_diagonal, b, x, d, c_d, c_z);
}

void CorotatedSystemOperator::chebyshev_step(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                             Eigen::VectorXd& d, double c_d, double c_z, Eigen::VectorXd&) const {
  fused_chebyshev_step(twin_, inverse_diagonal, b, x, d, c_d, c_z);
}

void CorotatedSystemOperator::multiply(const Eigen::VectorXf& x, Eigen::VectorXf& y) const {
  y.resize(rows());
  apply(single_, x, [&](VertexId v, const Eigen::Vector3f& sum) { y.segment<3>(3 * static_cast<Eigen::Index>(v)) = sum; });
}

void CorotatedSystemOperator::jacobi_residual(const std::vector<Mat3f>& inverse_diagonal, const Eigen::VectorXf& b,
                                              const Eigen::VectorXf& x, Eigen::VectorXf& z) const {
  fused_jacobi_residual(single_, inverse_diagonal, b, x, z);
}

void CorotatedSystemOperator::jacobi_residual(const std::vector<Mat3>& inverse_diagonal, const Eigen::VectorXd& b,
                                              const Eigen::VectorXd& x, Eigen::VectorXd& z) const {
  fused_jacobi_residual(twin_, inverse_diagonal, b, x, z);
}

void CorotatedSystemOperator::set_wide_cell_pass(bool on) {
  if (on && !avx512_cell_pass_supported())
    throw InputError("corotated system: the AVX-512 cell pass needs a CPU with AVX-512 F and DQ; this one has not");
  wide_cell_pass_ = on;
}
void CorotatedSystemOperator::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.resize(rows());
  apply(twin_, x, [&](VertexId v, const Eigen::Vector3d& sum) { y.segment<3>(3 * static_cast<Eigen::Index>(v)) = sum; });
}

double CorotatedSystemOperator::stress_coefficient(std::size_t cell, int a, int b) const {
  if (!with_tension_) return 0;
  double s = 0;
  for (std::size_t k = 0; k < 6; ++k) s += twin_.tension[cell][static_cast<Eigen::Index>(k)] * twin_.stress_basis[k](a, b);
  return s;
}

void CorotatedSystemOperator::split_corner_diagonals() {
  const std::size_t materials = twin_.stiffness.size();
  corner_diagonal_.assign(materials, {});
  for (std::size_t m = 0; m < materials; ++m)
    for (int a = 0; a < kCornerCount; ++a) {
      const Mat3 block = twin_.stiffness[m].block<3, 3>(3 * a, 3 * a);
      const Vec3 sign = 2.0 * corner_offset(a).cast<double>() - Vec3::Ones();
      const double along = block(0, 1) * sign[0] * sign[1];
      const double isotropic = block(0, 0) - along;
      const Mat3 split = isotropic * Mat3::Identity() + along * sign * sign.transpose();
      if ((split - block).cwiseAbs().maxCoeff() > 1e-13 * block.cwiseAbs().maxCoeff()) {
        corner_diagonal_.clear();
        return;
      }
      corner_diagonal_[m][static_cast<std::size_t>(a)] = {isotropic, along};
    }
}

std::vector<Mat3> CorotatedSystemOperator::inverse_diagonal_blocks() const {
  if (rotations_.empty() && !material_.empty()) throw InputError("corotated system: set_state must come before its block diagonal");
  const auto vertices = static_cast<std::size_t>(corner_slots_.start.size() - 1);
  const bool split = !corner_diagonal_.empty();
  std::vector<Mat3> out(vertices);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, static_cast<std::size_t>(kVerticesPerTask)),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t v = r.begin(); v < r.end(); ++v) {
                        if (vertex_held_[v] != 0) {  // identity rows
                          out[v] = Mat3::Identity();
                          continue;
                        }
                        Mat3 block = Mat3::Zero();
                        double stress_sum = 0;     // the stress stiffness's part: a multiple of I_3
                        double isotropic_sum = 0;  // the split blocks' isotropic part (R I R^T = I)
                        for (std::int32_t s = corner_slots_.start[v]; s < corner_slots_.start[v + 1]; ++s) {
                          const auto slot = corner_slots_.slot[static_cast<std::size_t>(s)];
                          const auto c = static_cast<std::size_t>(slot / 24);
                          const int a = slot % 24;
                          const Mat3& rotation = rotations_[c];
                          if (split) {  // R R^T = I: the rotations are polar factors
                            const CornerDiagonal& d = corner_diagonal_[material_[c]][static_cast<std::size_t>(a)];
                            const Vec3 turned = corner_sign_sum(rotation, a);
                            isotropic_sum += d.isotropic;
                            const Vec3 scaled = d.along_sign * turned;
                            for (int i = 0; i < 3; ++i)
                              for (int j = 0; j <= i; ++j) block(i, j) += scaled[i] * turned[j];
                          } else {
                            block.noalias() += rotation * twin_.stiffness[material_[c]].block<3, 3>(3 * a, 3 * a) * rotation.transpose();
                          }
                          if (with_tension_) stress_sum += twin_.tension[c].dot(stress_diagonal_basis_[static_cast<std::size_t>(a)]);
                        }
                        if (split) block.triangularView<Eigen::StrictlyUpper>() = block.transpose();
                        block.diagonal().array() += stress_sum + isotropic_sum;
                        const auto i = 3 * static_cast<Eigen::Index>(v);
                        block.diagonal() += twin_.mass_term.segment<3>(i);
                        if (!fixed_rows_.empty())
                          for (int axis = 0; axis < 3; ++axis)
                            if ((*fixed_)[static_cast<std::size_t>(i + axis)] != 0) {
                              block.row(axis).setZero();
                              block.col(axis).setZero();
                              block(axis, axis) = 1;
                            }
                        out[v] = inverse_or_identity(block);
                      }
                    });
  return out;
}

SparseMatrix CorotatedSystemOperator::assembled_matrix() const {
  if (rotations_.empty() && !material_.empty()) throw InputError("corotated system: set_state must come before assembled_matrix");
  SparseMatrix a = make_vertex_block_pattern(*volume_);
  const auto block = [&](CellId c, int a_corner, int b_corner) -> Mat3 {
    const auto ci = static_cast<std::size_t>(c);
    const Mat3& r = rotations_[ci];
    Mat3 m = r * twin_.stiffness[material_[ci]].block<3, 3>(3 * a_corner, 3 * b_corner) * r.transpose();
    m.diagonal().array() += stress_coefficient(ci, a_corner, b_corner);
    return m;
  };
  volume_->vertex_cells();
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, volume_->vertex_count()), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v != r.end(); ++v) gather_vertex_rows(*volume_, v, block, a);
  });
  for (Eigen::Index i = 0; i < a.rows(); ++i) a.coeffRef(i, i) += c_mass_ * (*mass_kg_)[i];
  if (!fixed_rows_.empty()) {
    FixedDofs held;
    held.fixed = *fixed_;
    held.value_mm = Vector::Zero(rows());
    Vector unused = Vector::Zero(rows());
    eliminate_fixed_dofs(a, unused, held);
  }
  return a;
}

}  // namespace cleave
