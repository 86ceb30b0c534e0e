#include "cleave/surface/corner_fans.hpp"

namespace cleave {
namespace {

/// Cell-local corners of face f on axis a, side s, as (u, v) bits of the two other axes
/// u = (a + 1) % 3, v = (a + 2) % 3 in the order (0,0), (1,0), (1,1), (0,1): counter-clockwise
/// seen from +a. The -a side uses the reverse order.
constexpr std::array<std::array<int, 2>, 4> kQuadUv = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};

int bit(int k, int axis) { return (k >> axis) & 1; }

}  // namespace

int quad_corner(Face f, int slot) {
  const int a = f / 2;
  const int side = f & 1;
  const int u = (a + 1) % 3;
  const int v = (a + 2) % 3;
  const auto& uv = kQuadUv[static_cast<size_t>(side == 1 ? slot : (4 - slot) % 4)];
  return (side << a) | (uv[0] << u) | (uv[1] << v);
}

int quad_slot(Face f, int corner) {
  for (int slot = 0; slot < 4; ++slot)
    if (quad_corner(f, slot) == corner) return slot;
  return -1;
}

std::vector<CornerFan> corner_fans(const LinkedVolume& volume, const Vec3i& g) {
  // Cell k around g has g as its corner k; its face on axis a through g is 2a + bit(k, a) and
  // separates it from cell k ^ (1 << a).
  std::array<CellId, 8> cells{};
  for (int k = 0; k < kCornerCount; ++k) cells[static_cast<size_t>(k)] = volume.cell_at_voxel(g - corner_offset(k));
  const auto face_of = [](int k, int a) { return 2 * a + bit(k, a); };
  const auto boundary = [&](int k, int a) {
    const CellId c = cells[static_cast<size_t>(k)];
    return c != kNone && is_boundary_face(volume, c, face_of(k, a));
  };

  std::array<std::array<bool, 3>, 8> visited{};
  std::vector<CornerFan> fans;
  for (int k0 = 0; k0 < kCornerCount; ++k0)
    for (int a0 = 0; a0 < 3; ++a0) {
      if (visited[static_cast<size_t>(k0)][static_cast<size_t>(a0)] || !boundary(k0, a0)) continue;
      CornerFan fan;
      int k = k0;
      int a = a0;
      int edge = a0 == 0 ? 1 : 0;  // leave the first face across its lower-axis edge
      do {
        visited[static_cast<size_t>(k)][static_cast<size_t>(a)] = true;
        fan.faces[static_cast<size_t>(fan.count)] = CellFace{cells[static_cast<size_t>(k)], face_of(k, a)};
        fan.cell_corner[static_cast<size_t>(fan.count)] = k;
        ++fan.count;
        // Walk around `edge` through linked cells, starting with the other face of cell k there.
        const int third = 3 - a - edge;
        int axis = third;
        int kk = k;
        while (volume.linked(cells[static_cast<size_t>(kk)], face_of(kk, axis))) {
          kk ^= 1 << axis;
          axis = axis == a ? third : a;
        }
        edge = 3 - axis - edge;  // continue across the next face's other edge
        k = kk;
        a = axis;
      } while ((k != k0 || a != a0) && fan.count < CornerFan::kMaxFaces);
      fans.push_back(fan);
    }
  return fans;
}

}  // namespace cleave
