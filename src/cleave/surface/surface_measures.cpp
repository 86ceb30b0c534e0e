#include "cleave/surface/surface_measures.hpp"

#include <Eigen/Geometry>

namespace cleave {

std::vector<Vec3> vertex_normals(const std::vector<std::array<std::int32_t, 3>>& triangles,
                                 const std::vector<Vec3>& positions_mm) {
  std::vector<Vec3> normals(positions_mm.size(), Vec3::Zero());
  for (const auto& t : triangles) {
    const Vec3& a = positions_mm[static_cast<size_t>(t[0])];
    const Vec3 n = (positions_mm[static_cast<size_t>(t[1])] - a).cross(positions_mm[static_cast<size_t>(t[2])] - a);
    for (std::int32_t v : t) normals[static_cast<size_t>(v)] += n;  // |n| = twice the area
  }
  for (Vec3& n : normals) {
    const double length = n.norm();
    n = length > 0 ? Vec3(n / length) : Vec3::Zero();
  }
  return normals;
}

double enclosed_volume_mm3(const std::vector<std::array<std::int32_t, 3>>& triangles,
                           const std::vector<Vec3>& positions_mm) {
  double six_volume = 0;
  for (const auto& t : triangles)
    six_volume += positions_mm[static_cast<size_t>(t[0])].dot(
        positions_mm[static_cast<size_t>(t[1])].cross(positions_mm[static_cast<size_t>(t[2])]));
  return six_volume / 6.0;
}

}  // namespace cleave
