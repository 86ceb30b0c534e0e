#include "cleave/fem/rigid_supports.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace cleave {
namespace {

using Vec6d = Eigen::Matrix<double, 6, 1>;
using Mat6d = Eigen::Matrix<double, 6, 6>;

/// A new rigid-mode row is independent when its part orthogonal to the rows held so far keeps
/// at least this fraction of its length.
constexpr double kIndependentFraction = 1e-6;

struct PieceFrame {
  Vec3 centre_mm = Vec3::Zero();
  double radius_mm = 0;  ///< scales rotations so that all 6 modes have comparable size
};

/// Displacement of dof (position p, axis) under the 6 rigid modes (3 translations, 3 rotations).
Vec6d rigid_row(const PieceFrame& frame, const Vec3& p_mm, int axis) {
  Vec6d row = Vec6d::Zero();
  row[axis] = 1.0;
  const Vec3 r = (p_mm - frame.centre_mm) / frame.radius_mm;
  for (int k = 0; k < 3; ++k) row[3 + k] = Vec3::Unit(k).cross(r)[axis];
  return row;
}

/// Orthonormal basis of the rigid-mode rows already held, grown by Gram-Schmidt.
struct HeldRows {
  std::vector<Vec6d> basis;
  Vec6d residual(Vec6d row) const {
    for (const Vec6d& q : basis) row -= q.dot(row) * q;
    return row;
  }
  bool add(const Vec6d& row) {
    if (basis.size() >= 6) return false;
    const Vec6d r = residual(row);
    if (r.norm() <= kIndependentFraction * row.norm()) return false;
    basis.push_back(r.normalized());
    return true;
  }
};

}  // namespace

std::vector<int> vertex_components(const LinkedVolume& volume) {
  const auto& comps = volume.cell_components();
  std::vector<int> out(static_cast<std::size_t>(volume.vertex_count()), 0);
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (const VertexId v : volume.cell_vertices(c)) out[static_cast<std::size_t>(v)] = comps[static_cast<std::size_t>(c)];
  return out;
}

namespace {

std::vector<PieceFrame> piece_frames(const LinkedVolume& volume, const std::vector<int>& comp_of_vertex, int pieces) {
  std::vector<PieceFrame> frames(static_cast<std::size_t>(pieces));
  std::vector<int> counts(static_cast<std::size_t>(pieces), 0);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const auto p = static_cast<std::size_t>(comp_of_vertex[static_cast<std::size_t>(v)]);
    frames[p].centre_mm += volume.vertex_position_mm(v);
    ++counts[p];
  }
  for (std::size_t p = 0; p < frames.size(); ++p) frames[p].centre_mm /= std::max(counts[p], 1);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    auto& f = frames[static_cast<std::size_t>(comp_of_vertex[static_cast<std::size_t>(v)])];
    f.radius_mm = std::max(f.radius_mm, (volume.vertex_position_mm(v) - f.centre_mm).norm());
  }
  for (auto& f : frames) f.radius_mm = std::max(f.radius_mm, volume.grid().cell_size_mm);
  return frames;
}

}  // namespace

RigidSupportReport add_rigid_supports(const LinkedVolume& volume, FixedDofs& fixed) {
  const int pieces = volume.component_count();
  const std::vector<int> comp = vertex_components(volume);
  const std::vector<PieceFrame> frames = piece_frames(volume, comp, pieces);
  std::vector<HeldRows> held(static_cast<std::size_t>(pieces));
  std::vector<int> fixed_count(static_cast<std::size_t>(pieces), 0);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const auto p = static_cast<std::size_t>(comp[static_cast<std::size_t>(v)]);
    for (int i = 0; i < 3; ++i) {
      if (fixed.fixed[static_cast<std::size_t>(3 * v + i)] == 0) continue;
      ++fixed_count[p];
      if (held[p].basis.size() < 6) held[p].add(rigid_row(frames[p], volume.vertex_position_mm(v), i));
    }
  }

  // Far-apart candidate vertices per piece: A farthest from the centre, B farthest from A,
  // C farthest from the line AB.
  std::vector<std::array<VertexId, 3>> anchors(static_cast<std::size_t>(pieces), {kNone, kNone, kNone});
  std::vector<std::array<double, 3>> best(static_cast<std::size_t>(pieces), {-1.0, -1.0, -1.0});
  for (int stage = 0; stage < 3; ++stage)
    for (VertexId v = 0; v < volume.vertex_count(); ++v) {
      const auto p = static_cast<std::size_t>(comp[static_cast<std::size_t>(v)]);
      if (held[p].basis.size() >= 6) continue;
      const Vec3 x = volume.vertex_position_mm(v);
      double score = 0;
      if (stage == 0) {
        score = (x - frames[p].centre_mm).norm();
      } else {
        const Vec3 a = volume.vertex_position_mm(anchors[p][0]);
        if (stage == 1) {
          score = (x - a).norm();
        } else {
          const Vec3 ab = volume.vertex_position_mm(anchors[p][1]) - a;
          score = ab.norm() > 0 ? (x - a).cross(ab).norm() / ab.norm() : (x - a).norm();
        }
      }
      if (score > best[p][static_cast<std::size_t>(stage)]) {
        best[p][static_cast<std::size_t>(stage)] = score;
        anchors[p][static_cast<std::size_t>(stage)] = v;
      }
    }

  RigidSupportReport report;
  for (int p = 0; p < pieces; ++p) {
    const auto pi = static_cast<std::size_t>(p);
    if (fixed_count[pi] == 0) report.free_components.push_back(p);
    while (held[pi].basis.size() < 6) {
      int chosen_dof = -1;
      double chosen_norm = 0;
      for (const VertexId v : anchors[pi])
        for (int i = 0; i < 3; ++i) {
          if (v == kNone || fixed.fixed[static_cast<std::size_t>(3 * v + i)] != 0) continue;
          const double n = held[pi].residual(rigid_row(frames[pi], volume.vertex_position_mm(v), i)).norm();
          if (n > chosen_norm) {
            chosen_norm = n;
            chosen_dof = 3 * v + i;
          }
        }
      if (chosen_dof < 0 || !held[pi].add(rigid_row(frames[pi], volume.vertex_position_mm(chosen_dof / 3), chosen_dof % 3)))
        break;
      fixed.fixed[static_cast<std::size_t>(chosen_dof)] = 1;
      fixed.value_mm[chosen_dof] = 0.0;
      ++report.added_dofs;
    }
  }
  return report;
}

void remove_rigid_motion(const LinkedVolume& volume, std::span<const int> components, const Vector& weights, Vector& u) {
  if (components.empty()) return;
  const int pieces = volume.component_count();
  const std::vector<int> comp = vertex_components(volume);
  const std::vector<PieceFrame> frames = piece_frames(volume, comp, pieces);
  std::vector<std::uint8_t> wanted(static_cast<std::size_t>(pieces), 0);
  for (const int p : components) wanted[static_cast<std::size_t>(p)] = 1;
  std::vector<Mat6d> gram(static_cast<std::size_t>(pieces), Mat6d::Zero());
  std::vector<Vec6d> moment(static_cast<std::size_t>(pieces), Vec6d::Zero());
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const auto p = static_cast<std::size_t>(comp[static_cast<std::size_t>(v)]);
    if (!wanted[p]) continue;
    for (int i = 0; i < 3; ++i) {
      const Vec6d row = rigid_row(frames[p], volume.vertex_position_mm(v), i);
      const double w = weights[3 * v + i];
      gram[p] += w * row * row.transpose();
      moment[p] += w * u[3 * v + i] * row;
    }
  }
  std::vector<Vec6d> coefficients(static_cast<std::size_t>(pieces), Vec6d::Zero());
  for (const int p : components) coefficients[static_cast<std::size_t>(p)] = gram[static_cast<std::size_t>(p)].ldlt().solve(moment[static_cast<std::size_t>(p)]);
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const auto p = static_cast<std::size_t>(comp[static_cast<std::size_t>(v)]);
    if (!wanted[p]) continue;
    for (int i = 0; i < 3; ++i) u[3 * v + i] -= rigid_row(frames[p], volume.vertex_position_mm(v), i).dot(coefficients[p]);
  }
}

}  // namespace cleave
