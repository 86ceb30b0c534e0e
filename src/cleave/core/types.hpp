#pragma once
// Small fixed-size types used across cleave (Eigen-backed).
#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace cleave {

using Vec3 = Eigen::Vector3d;   ///< a point or vector; positions in mm
using Vec3f = Eigen::Vector3f;
using Vec3i = Eigen::Vector3i;  ///< integer grid coordinates (voxel or grid corner)
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;  ///< symmetric tensor in Voigt order xx, yy, zz, xy, xz, yz

using CellId = std::int32_t;    ///< index of an active hexahedral cell; -1 = none
using VertexId = std::int32_t;  ///< index of a simulation vertex; -1 = none
inline constexpr std::int32_t kNone = -1;

/// Voigt vector (xx, yy, zz, xy, xz, yz) of a symmetric 3x3 tensor.
inline Vec6 to_voigt(const Mat3& s) {
  Vec6 v;
  v << s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(0, 2), s(1, 2);
  return v;
}

/// Symmetric 3x3 tensor from its Voigt vector (xx, yy, zz, xy, xz, yz).
inline Mat3 from_voigt(const Vec6& v) {
  Mat3 s;
  s << v[0], v[3], v[4],  //
      v[3], v[1], v[5],   //
      v[4], v[5], v[2];
  return s;
}

}  // namespace cleave
