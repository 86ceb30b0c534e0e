#include "cleave/surface/render_surface.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <functional>

#include "cleave/core/error.hpp"
#include "cleave/surface/corner_fans.hpp"
#include "cleave/surface/surface_vertex_placement.hpp"

namespace cleave {
namespace {

size_t face_key(CellId c, Face f) { return static_cast<size_t>(c) * kFaceCount + static_cast<size_t>(f); }

SurfaceField field_of(const TissueModel& model, const RenderSurface& surface) {
  if (model.labels.has_distance())
    return {&model.labels.grid, &model.labels.corner_distance_mm, kDistanceFieldMaxShiftCells};
  return {&model.labels.grid, &surface.mask_distance_mm, kMaskFieldMaxShiftCells};
}

void check_model(const TissueModel& model) {
  const GridSpec& a = model.labels.grid;
  const GridSpec& b = model.volume.grid();
  if (a.dims != b.dims || (model.labels.has_distance() &&
                           model.labels.corner_distance_mm.size() != static_cast<size_t>(a.corner_count())))
    throw ComputeError(fmt::format("render surface: the model's label grid {}x{}x{} does not match its linked volume "
                                   "{}x{}x{} or its corner distances",
                                   a.dims.x(), a.dims.y(), a.dims.z(), b.dims.x(), b.dims.y(), b.dims.z()));
}

/// Writes the two triangles of quad q along its stored diagonal.
void write_triangles(RenderSurface& s, size_t q) {
  const auto& v = s.quads[q].vertices;
  if (s.quads[q].diagonal == 0) {
    s.triangles[2 * q] = {v[0], v[1], v[2]};
    s.triangles[2 * q + 1] = {v[0], v[2], v[3]};
  } else {
    s.triangles[2 * q] = {v[0], v[1], v[3]};
    s.triangles[2 * q + 1] = {v[1], v[2], v[3]};
  }
}

/// Chooses the diagonal of quad q (the shorter one in reference positions) and writes its
/// triangles. A cut face and the face opposite it share the vertices where the cut ends (the
/// crack front); a diagonal joining two shared vertices would give both quads the same edge, so
/// it is avoided, and where all four corners are shared the two sides take different diagonals
/// (the cell with the lower id keeps the shorter one). Slots 0 and 2 of a face and of its
/// opposite face are the same grid corners, so the diagonal flag means the same corners on both.
void set_triangles(RenderSurface& s, const LinkedVolume& volume, size_t q) {
  SurfaceQuad& quad = s.quads[q];
  const auto& v = quad.vertices;
  const auto at = [&](int i) -> const Vec3& { return s.reference_mm[static_cast<size_t>(v[static_cast<size_t>(i)])]; };
  std::uint8_t diagonal = (at(1) - at(3)).squaredNorm() < (at(0) - at(2)).squaredNorm() ? 1 : 0;
  if (quad.is_cut) {
    const CellId other = volume.neighbor(quad.cell, quad.face);
    const std::int32_t oq = s.quad_of_face[face_key(other, opposite(quad.face))];
    if (oq != kNone) {
      const auto& w = s.quads[static_cast<size_t>(oq)].vertices;
      std::array<bool, 4> shared{};
      for (size_t i = 0; i < 4; ++i) shared[i] = v[i] != kNone && v[i] == w[(4 - i) % 4];
      const bool diagonal0_shared = shared[0] && shared[2];
      const bool diagonal1_shared = shared[1] && shared[3];
      if (diagonal0_shared && diagonal1_shared) diagonal = quad.cell < other ? diagonal : static_cast<std::uint8_t>(1 - diagonal);
      else if (diagonal0_shared) diagonal = 1;
      else if (diagonal1_shared) diagonal = 0;
    }
  }
  quad.diagonal = diagonal;
  write_triangles(s, q);
}

void add_quad(RenderSurface& s, const LinkedVolume& volume, CellId c, Face f) {
  s.quad_of_face[face_key(c, f)] = static_cast<std::int32_t>(s.quads.size());
  s.quads.push_back(SurfaceQuad{c, f, volume.neighbor(c, f) != kNone, {kNone, kNone, kNone, kNone}, 0});
  s.triangles.push_back({kNone, kNone, kNone});
  s.triangles.push_back({kNone, kNone, kNone});
}

void remove_quad(RenderSurface& s, size_t q) {
  const SurfaceQuad& removed = s.quads[q];
  s.quad_of_face[face_key(removed.cell, removed.face)] = kNone;
  const size_t last = s.quads.size() - 1;
  if (q != last) {
    s.quads[q] = s.quads[last];
    s.triangles[2 * q] = s.triangles[2 * last];
    s.triangles[2 * q + 1] = s.triangles[2 * last + 1];
    s.quad_of_face[face_key(s.quads[q].cell, s.quads[q].face)] = static_cast<std::int32_t>(q);
  }
  s.quads.pop_back();
  s.triangles.resize(2 * s.quads.size());
}

/// Creates one vertex per fan at grid corner g and writes it into the fans' quads.
void add_corner_vertices(RenderSurface& s, const LinkedVolume& volume, const SurfaceField& field, const Vec3i& g) {
  for (const CornerFan& fan : corner_fans(volume, g)) {
    const VertexPlacement placement = place_fan_vertex(volume, field, g, fan);
    const auto id = s.vertex_count();
    s.reference_mm.push_back(placement.position_mm);
    s.cell.push_back(placement.cell);
    s.xi.push_back(placement.xi);
    s.grid_corner.push_back(g);
    for (int i = 0; i < fan.count; ++i) {
      const CellFace& f = fan.faces[static_cast<size_t>(i)];
      const std::int32_t q = s.quad_of_face[face_key(f.cell, f.face)];
      s.quads[static_cast<size_t>(q)].vertices[static_cast<size_t>(quad_slot(f.face, fan.cell_corner[static_cast<size_t>(i)]))] = id;
    }
  }
}

/// Calls fn(quad index, slot) for every quad slot at grid corner g.
template <typename Fn>
void for_each_quad_slot_at(const RenderSurface& s, const LinkedVolume& volume, const Vec3i& g, Fn&& fn) {
  for (int k = 0; k < kCornerCount; ++k) {
    const CellId c = volume.cell_at_voxel(g - corner_offset(k));
    if (c == kNone) continue;
    for (int a = 0; a < 3; ++a) {
      const Face f = 2 * a + ((k >> a) & 1);
      const std::int32_t q = s.quad_of_face[face_key(c, f)];
      if (q != kNone) fn(static_cast<size_t>(q), quad_slot(f, k));
    }
  }
}

/// Removes vertex `dead` (no quad uses it) by moving the last vertex into its place.
void remove_vertex(RenderSurface& s, const LinkedVolume& volume, SurfaceVertexId dead) {
  const SurfaceVertexId last = s.vertex_count() - 1;
  if (dead != last) {
    const auto d = static_cast<size_t>(dead);
    const auto l = static_cast<size_t>(last);
    s.reference_mm[d] = s.reference_mm[l];
    s.cell[d] = s.cell[l];
    s.xi[d] = s.xi[l];
    s.grid_corner[d] = s.grid_corner[l];
    for_each_quad_slot_at(s, volume, s.grid_corner[d], [&](size_t q, int slot) {
      SurfaceVertexId& v = s.quads[q].vertices[static_cast<size_t>(slot)];
      if (v != last) return;
      v = dead;
      write_triangles(s, q);
    });
  }
  s.reference_mm.pop_back();
  s.cell.pop_back();
  s.xi.pop_back();
  s.grid_corner.pop_back();
}

}  // namespace

RenderSurface build_render_surface(const TissueModel& model) {
  check_model(model);
  const LinkedVolume& volume = model.volume;
  RenderSurface s;
  if (!model.labels.has_distance()) s.mask_distance_mm = mask_distance_field(model.labels);
  const SurfaceField field = field_of(model, s);
  s.quad_of_face.assign(static_cast<size_t>(volume.cell_count()) * kFaceCount, kNone);
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f = 0; f < kFaceCount; ++f)
      if (is_boundary_face(volume, c, f)) add_quad(s, volume, c, f);
  for (size_t q = 0; q < s.quads.size(); ++q)
    for (int slot = 0; slot < 4; ++slot) {
      const SurfaceQuad& quad = s.quads[q];
      if (quad.vertices[static_cast<size_t>(slot)] != kNone) continue;
      add_corner_vertices(s, volume, field, volume.cell_voxel(quad.cell) + corner_offset(quad_corner(quad.face, slot)));
    }
  for (size_t q = 0; q < s.quads.size(); ++q) set_triangles(s, volume, q);
  return s;
}

void update_render_surface(RenderSurface& s, const TissueModel& model, const CutReport& report) {
  check_model(model);
  const LinkedVolume& volume = model.volume;
  const GridSpec& grid = volume.grid();
  if (s.quad_of_face.size() != static_cast<size_t>(volume.cell_count()) * kFaceCount)
    throw ComputeError(fmt::format("render surface of {} cell faces cannot be updated for a model of {} cells",
                                   s.quad_of_face.size(), volume.cell_count()));
  if (report.touched_cells.empty()) return;
  const SurfaceField field = field_of(model, s);

  // Grid corners whose fans may have changed, and the cell faces through them.
  std::vector<std::int64_t> corners;
  for (CellId c : report.touched_cells)
    for (int k = 0; k < kCornerCount; ++k) corners.push_back(grid.corner_index(volume.cell_voxel(c) + corner_offset(k)));
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const auto affected = [&](const Vec3i& g) { return std::binary_search(corners.begin(), corners.end(), grid.corner_index(g)); };
  const std::int64_t nx = grid.dims.x() + 1;
  const std::int64_t ny = grid.dims.y() + 1;
  std::vector<Vec3i> corner_points;
  corner_points.reserve(corners.size());
  for (std::int64_t index : corners)
    corner_points.emplace_back(static_cast<int>(index % nx), static_cast<int>((index / nx) % ny),
                               static_cast<int>(index / (nx * ny)));
  std::vector<CellFace> faces;
  for (const Vec3i& g : corner_points)
    for (int k = 0; k < kCornerCount; ++k) {
      const CellId c = volume.cell_at_voxel(g - corner_offset(k));
      if (c == kNone) continue;
      for (int a = 0; a < 3; ++a) faces.push_back(CellFace{c, 2 * a + ((k >> a) & 1)});
    }
  std::sort(faces.begin(), faces.end(), [](const CellFace& a, const CellFace& b) {
    return face_key(a.cell, a.face) < face_key(b.cell, b.face);
  });
  faces.erase(std::unique(faces.begin(), faces.end(),
                          [](const CellFace& a, const CellFace& b) { return a.cell == b.cell && a.face == b.face; }),
              faces.end());

  // Remove the quads through those corners; keep their vertices at unaffected corners.
  std::vector<std::array<SurfaceVertexId, 4>> kept(faces.size(), {kNone, kNone, kNone, kNone});
  std::vector<SurfaceVertexId> dead;
  for (size_t i = 0; i < faces.size(); ++i) {
    const std::int32_t q = s.quad_of_face[face_key(faces[i].cell, faces[i].face)];
    if (q == kNone) continue;
    const SurfaceQuad& quad = s.quads[static_cast<size_t>(q)];
    for (int slot = 0; slot < 4; ++slot) {
      const Vec3i g = volume.cell_voxel(quad.cell) + corner_offset(quad_corner(quad.face, slot));
      const SurfaceVertexId v = quad.vertices[static_cast<size_t>(slot)];
      if (affected(g)) dead.push_back(v);
      else kept[i][static_cast<size_t>(slot)] = v;
    }
    remove_quad(s, static_cast<size_t>(q));
  }

  // New quads for the faces that are on the surface now, then new vertices at the corners.
  const size_t first_new = s.quads.size();
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!is_boundary_face(volume, faces[i].cell, faces[i].face)) continue;
    add_quad(s, volume, faces[i].cell, faces[i].face);
    SurfaceQuad& quad = s.quads.back();
    for (int slot = 0; slot < 4; ++slot) {
      const Vec3i g = volume.cell_voxel(quad.cell) + corner_offset(quad_corner(quad.face, slot));
      if (affected(g)) continue;
      if (kept[i][static_cast<size_t>(slot)] == kNone)
        throw ComputeError(fmt::format("render surface update: cell {} face {} became a boundary face without a cut "
                                       "reported at all its corners",
                                       quad.cell, quad.face));
      quad.vertices[static_cast<size_t>(slot)] = kept[i][static_cast<size_t>(slot)];
    }
  }
  for (const Vec3i& g : corner_points) add_corner_vertices(s, volume, field, g);
  for (size_t q = first_new; q < s.quads.size(); ++q) set_triangles(s, volume, q);

  // Drop the old vertices of the affected corners (highest id first keeps the others valid).
  std::sort(dead.begin(), dead.end(), std::greater<>());
  dead.erase(std::unique(dead.begin(), dead.end()), dead.end());
  for (SurfaceVertexId v : dead) remove_vertex(s, volume, v);
}

std::vector<Vec3> deformed_positions(const RenderSurface& surface, const LinkedVolume& volume,
                                     const std::vector<Vec3>& displacement_mm) {
  if (displacement_mm.empty()) return surface.reference_mm;
  if (displacement_mm.size() != static_cast<size_t>(volume.vertex_count()))
    throw InputError(fmt::format("displacement has {} vectors; expected one per vertex of the linked volume ({})",
                                 displacement_mm.size(), volume.vertex_count()));
  std::vector<Vec3> positions(surface.reference_mm.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const Vec3& t = surface.xi[i];
    const auto& vertices = volume.cell_vertices(surface.cell[i]);
    Vec3 u = Vec3::Zero();
    for (int k = 0; k < kCornerCount; ++k)
      u += trilinear_corner_weight(k, t) * displacement_mm[static_cast<size_t>(vertices[static_cast<size_t>(k)])];
    positions[i] = surface.reference_mm[i] + u;
  }
  return positions;
}

}  // namespace cleave
