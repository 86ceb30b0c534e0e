#include "cleave/fem/rigid_supports.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"

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

struct RigidMotionRemover::Piece {
  PieceFrame frame;
  Eigen::LDLT<Mat6d> normal_equations;  ///< of the weighted least-squares fit of the 6 rigid modes
};

RigidMotionRemover::RigidMotionRemover(const LinkedVolume& volume, std::span<const int> components, Vector weights)
    : weights_(std::move(weights)) {
  if (weights_.size() != 3 * static_cast<Eigen::Index>(volume.vertex_count()))
    throw InputError(fmt::format("rigid motion weights hold {} values; expected one per dof ({})", weights_.size(),
                                 3 * static_cast<Eigen::Index>(volume.vertex_count())));
  const int pieces = volume.component_count();
  std::vector<int> index_of_piece(static_cast<std::size_t>(pieces), -1);
  for (const int p : components) {
    if (p < 0 || p >= pieces)
      throw InputError(fmt::format("component {} does not exist; expected 0 to {}", p, pieces - 1));
    if (index_of_piece[static_cast<std::size_t>(p)] >= 0) continue;  // listed twice
    index_of_piece[static_cast<std::size_t>(p)] = static_cast<int>(pieces_.size());
    pieces_.emplace_back();
  }
  if (pieces_.empty()) return;
  const std::vector<int> comp = vertex_components(volume);
  const std::vector<PieceFrame> frames = piece_frames(volume, comp, pieces);
  piece_of_vertex_.resize(comp.size());
  for (std::size_t v = 0; v < comp.size(); ++v) piece_of_vertex_[v] = index_of_piece[static_cast<std::size_t>(comp[v])];
  for (int p = 0; p < pieces; ++p)
    if (const int i = index_of_piece[static_cast<std::size_t>(p)]; i >= 0) pieces_[static_cast<std::size_t>(i)].frame = frames[static_cast<std::size_t>(p)];
  std::vector<Mat6d> gram(pieces_.size(), Mat6d::Zero());
  offset_.assign(comp.size(), Vec3::Zero());
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const int i = piece_of_vertex_[static_cast<std::size_t>(v)];
    if (i < 0) continue;
    const PieceFrame& frame = pieces_[static_cast<std::size_t>(i)].frame;
    offset_[static_cast<std::size_t>(v)] = (volume.vertex_position_mm(v) - frame.centre_mm) / frame.radius_mm;
    for (int axis = 0; axis < 3; ++axis) {
      const Vec6d row = rigid_row(frame, volume.vertex_position_mm(v), axis);
      gram[static_cast<std::size_t>(i)] += weights_[3 * v + axis] * row * row.transpose();
    }
  }
  for (std::size_t i = 0; i < pieces_.size(); ++i) pieces_[i].normal_equations.compute(gram[i]);
}

RigidMotionRemover::~RigidMotionRemover() = default;
RigidMotionRemover::RigidMotionRemover(RigidMotionRemover&&) noexcept = default;
RigidMotionRemover& RigidMotionRemover::operator=(RigidMotionRemover&&) noexcept = default;

void RigidMotionRemover::remove(Vector& u) const {
  if (u.size() != weights_.size())
    throw InputError(fmt::format("displacement holds {} values; expected one per dof ({})", u.size(), weights_.size()));
  if (pieces_.empty()) return;
  // With r the vertex's scaled offset from its piece's centre, rigid_row's rows give the moments
  // sum w u (translations) and sum r x (w u) (rotations), and the fitted motion t + theta x r:
  // one pass each way, no rows formed and no positions recomputed (4.5 -> 0.5 ms at 52,000
  // vertices, the free tube's preview).
  std::vector<Vec6d> moment(pieces_.size(), Vec6d::Zero());
  const auto vertices = static_cast<VertexId>(piece_of_vertex_.size());
  for (VertexId v = 0; v < vertices; ++v) {
    const int i = piece_of_vertex_[static_cast<std::size_t>(v)];
    if (i < 0) continue;
    const Vec3 weighted = weights_.segment<3>(3 * v).cwiseProduct(u.segment<3>(3 * v));
    Vec6d& m = moment[static_cast<std::size_t>(i)];
    m.head<3>() += weighted;
    m.tail<3>() += offset_[static_cast<std::size_t>(v)].cross(weighted);
  }
  std::vector<Vec6d> coefficients(pieces_.size());
  for (std::size_t i = 0; i < pieces_.size(); ++i) coefficients[i] = pieces_[i].normal_equations.solve(moment[i]);
  for (VertexId v = 0; v < vertices; ++v) {
    const int i = piece_of_vertex_[static_cast<std::size_t>(v)];
    if (i < 0) continue;
    const Vec6d& c = coefficients[static_cast<std::size_t>(i)];
    u.segment<3>(3 * v) -= c.head<3>() + Vec3(c.tail<3>()).cross(offset_[static_cast<std::size_t>(v)]);
  }
}

}  // namespace cleave
