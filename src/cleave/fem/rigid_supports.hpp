#pragma once
// Rigid-body motions of the connected pieces of a (cut) linked volume. A piece that no fixed
// vertex holds (or that its fixed dofs do not hold against every rigid motion) makes K singular.
// add_rigid_supports holds the fewest extra dofs (at most 6 per piece, chosen far apart: the
// classic 3-2-1 support) so that every piece is well posed. For a self-equilibrated load such as
// T sigma (zero net force and moment on each piece) these supports carry no reaction, so the
// deformation is exact; RigidMotionRemover then removes the arbitrary rigid part.
#include <span>
#include <vector>

#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/grid/linked_volume.hpp"

namespace cleave {

struct RigidSupportReport {
  std::vector<int> free_components;  ///< pieces with no fixed dof before the call
  int added_dofs = 0;                ///< dofs held by this call
};

/// Adds zero-displacement supports to `fixed` until each component's rigid motions are held.
RigidSupportReport add_rigid_supports(const LinkedVolume& volume, FixedDofs& fixed);

/// Subtracts from displacements `u` (3 n_v) the rigid motion of each listed component that best
/// fits it in the `weights`-weighted least-squares sense (weights per dof, e.g. the lumped mass):
/// afterwards the piece's weighted mean displacement and mean infinitesimal rotation are zero.
/// For many displacements of one volume (a StaticSolver's solves) the vertices' pieces, the
/// pieces' frames and their weighted normal equations are set up once, so that each removal is
/// one pass over the listed pieces' vertices.
///
///   RigidMotionRemover remover(volume, free_components, lumped_mass(model));
///   remover.remove(u);
class RigidMotionRemover {
 public:
  /// The volume's topology and positions are read here only: the remover serves displacements of
  /// that topology. InputError for weights that are not one per dof or components that do not exist.
  RigidMotionRemover(const LinkedVolume& volume, std::span<const int> components, Vector weights);
  ~RigidMotionRemover();
  RigidMotionRemover(RigidMotionRemover&&) noexcept;
  RigidMotionRemover& operator=(RigidMotionRemover&&) noexcept;

  /// InputError when `u` does not hold one value per dof.
  void remove(Vector& u) const;

 private:
  struct Piece;
  std::vector<int> piece_of_vertex_;  ///< index into pieces_; -1 where the vertex's piece is left alone
  std::vector<Piece> pieces_;
  std::vector<Vec3> offset_;  ///< per vertex of a listed piece: (position - piece centre) / piece radius
  Vector weights_;
};

/// Component of every vertex (the component of its cells).
std::vector<int> vertex_components(const LinkedVolume& volume);

}  // namespace cleave
