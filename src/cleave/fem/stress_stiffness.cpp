#include "cleave/fem/stress_stiffness.hpp"

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <optional>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotated_cells_avx512.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/tensile_part_avx512.hpp"

namespace cleave {
namespace {

/// All principal minors non-negative (Sylvester's criterion for semi-definiteness).
bool positive_semidefinite(const Vec6& s) {
  return s[0] >= 0 && s[1] >= 0 && s[2] >= 0 && s[0] * s[1] >= s[3] * s[3] && s[0] * s[2] >= s[4] * s[4] &&
         s[1] * s[2] >= s[5] * s[5] && from_voigt(s).determinant() >= 0;
}

/// The tensile part where the stress is semi-definite (most cells of tissue under tension are
/// wholly tensile, the rest often wholly compressive); none where it is mixed in sign.
std::optional<Vec6> definite_tensile_part(const Vec6& stress_kPa) {
  if (positive_semidefinite(stress_kPa)) return stress_kPa;
  if (positive_semidefinite(-stress_kPa)) return Vec6::Zero();
  return std::nullopt;
}

/// The tensile part of a stress mixed in sign, by Eigen's closed-form decomposition.
Vec6 mixed_tensile_part(const Vec6& stress_kPa) {
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(from_voigt(stress_kPa));
  const Mat3& axes = eigen.eigenvectors();
  return to_voigt(axes * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() * axes.transpose());
}

/// The mixed cells of one range, their tensile parts taken 8 at a time in AVX-512 lanes where the
/// CPU has them (fem/tensile_part_avx512.hpp), one by one with Eigen's closed form elsewhere.
class MixedCells {
 public:
  explicit MixedCells(std::vector<Vec6>& tension_kPa) : tension_kPa_(tension_kPa) {}
  void add(CellId c, const Vec6& stress_kPa) {
    stress_[count_] = stress_kPa;
    cell_[count_] = static_cast<std::size_t>(c);
    if (++count_ == kLanes) flush();
  }
  void flush() {
    if (count_ == 0) return;
    if (avx512_cell_pass_supported()) {
      std::array<Vec6, kLanes> out;
      tensile_parts_avx512(stress_[0].data(), out[0].data(), static_cast<int>(count_), JacobiSweeps{});
      for (std::size_t i = 0; i < count_; ++i) tension_kPa_[cell_[i]] = out[i];
    } else {
      for (std::size_t i = 0; i < count_; ++i) tension_kPa_[cell_[i]] = mixed_tensile_part(stress_[i]);
    }
    count_ = 0;
  }

 private:
  static constexpr std::size_t kLanes = 8;
  std::vector<Vec6>& tension_kPa_;
  std::array<Vec6, kLanes> stress_;
  std::array<std::size_t, kLanes> cell_{};
  std::size_t count_ = 0;
};

/// Rotation and tensile stress of cells [begin, end) (cell_rotations_and_tension's work per task).
void rotations_and_tension_in_range(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                    const Vector& displacement_mm, CellId begin, CellId end, std::vector<Mat3>& rotations,
                                    std::vector<Vec6>& tension_kPa) {
  MixedCells mixed(tension_kPa);
  cell_frames_in_range(volume, displacement_mm, begin, end, rotations, [&](CellId c, const Mat3& f) {
    const auto ci = static_cast<std::size_t>(c);
    Vec6 stress = table.of_label(volume.cell_label(c)).elasticity_kPa * corotated_strain(f, rotations[ci]);
    if (!residual_stress_kPa.empty()) stress += residual_stress_kPa[ci];
    if (const std::optional<Vec6> definite = definite_tensile_part(stress)) tension_kPa[ci] = *definite;
    else mixed.add(c, stress);
  });
  mixed.flush();
}

}  // namespace

Vec6 tensile_part(const Vec6& stress_kPa) {
  if (const std::optional<Vec6> definite = definite_tensile_part(stress_kPa)) return *definite;
  return mixed_tensile_part(stress_kPa);
}

void cell_rotations_and_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                const Vector& displacement_mm, std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa) {
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  rotations.resize(cells);
  tension_kPa.resize(cells);
  tbb::parallel_for(tbb::blocked_range<CellId>(0, volume.cell_count()), [&](const tbb::blocked_range<CellId>& r) {
    rotations_and_tension_in_range(volume, table, residual_stress_kPa, displacement_mm, r.begin(), r.end(), rotations, tension_kPa);
  });
}

void cell_rotations_and_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                const Vector& displacement_mm, std::span<const CellRange> cell_ranges,
                                std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa) {
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  if (rotations.size() != cells || tension_kPa.size() != cells)
    throw InputError(fmt::format("rotations and tension over cell ranges: {} rotations and {} tensions for {} cells; expected one "
                                 "each per cell", rotations.size(), tension_kPa.size(), cells));
  require_ranges_within(cell_ranges, cells, "rotations and tension over cell ranges");
  for_each_cell_range(cell_ranges, [&](std::size_t begin, std::size_t end) {
    rotations_and_tension_in_range(volume, table, residual_stress_kPa, displacement_mm, static_cast<CellId>(begin),
                                   static_cast<CellId>(end), rotations, tension_kPa);
  });
}

}  // namespace cleave
