#pragma once
// Test fixtures for the io tests: a temporary folder, an icosphere mesh written in each mesh
// format by independent writers, hand-written NRRD files, and the paths of the real data.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <unistd.h>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cleave/core/error.hpp"
#include "cleave/core/types.hpp"
#include "cleave/io/surface_mesh_file.hpp"

namespace cleave::test {

/// A fresh folder under the system temp dir, removed when the fixture goes away.
struct TempFolder {
  std::filesystem::path path;
  TempFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::temp_directory_path() /
           ("cleave_io_" + std::string(info ? info->name() : "test") + "_" + std::to_string(getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::filesystem::path operator/(const std::string& name) const { return path / name; }
};

/// The message of the InputError `f` throws, or "no InputError" (for exact-message assertions).
inline std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

inline void write_bytes(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out << bytes;
}

inline std::string read_bytes(const std::filesystem::path& file) {
  std::string bytes(static_cast<size_t>(std::filesystem::file_size(file)), '\0');
  std::ifstream in(file, std::ios::binary);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

/// Icosahedron subdivided `levels` times, vertices projected onto the sphere (centre, radius).
/// Level 4: 2562 vertices, 5120 triangles; its volume is 0.4% below the sphere's.
inline TriangleMesh icosphere(const Vec3& centre, double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[static_cast<size_t>(a)] + v[static_cast<size_t>(b)]).normalized());
      return midpoint[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& [a, b, c] : f) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  TriangleMesh mesh;
  for (const auto& p : v) mesh.vertices_mm.push_back(centre + radius * p);
  mesh.triangles = f;
  return mesh;
}

inline std::string to_obj(const TriangleMesh& m) {
  std::string s = "# icosphere\n";
  for (const auto& p : m.vertices_mm) s += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  for (const auto& t : m.triangles)
    s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return s;
}

inline std::string to_off(const TriangleMesh& m) {
  std::string s = "OFF\n" + std::to_string(m.vertices_mm.size()) + " " + std::to_string(m.triangles.size()) + " 0\n";
  for (const auto& p : m.vertices_mm) s += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  for (const auto& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

inline std::string to_ascii_ply(const TriangleMesh& m) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(m.vertices_mm.size()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(m.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : m.vertices_mm) s += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  for (const auto& t : m.triangles)
    s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

/// Binary STL (little-endian floats), the common form of STL files.
inline std::string to_binary_stl(const TriangleMesh& m) {
  std::string s(80, ' ');
  auto put_u32 = [&](std::uint32_t x) { s.append(reinterpret_cast<const char*>(&x), 4); };
  auto put_f32 = [&](double x) {
    const auto f = static_cast<float>(x);
    s.append(reinterpret_cast<const char*>(&f), 4);
  };
  put_u32(static_cast<std::uint32_t>(m.triangles.size()));
  for (const auto& t : m.triangles) {
    const Vec3& a = m.vertices_mm[static_cast<size_t>(t[0])];
    const Vec3& b = m.vertices_mm[static_cast<size_t>(t[1])];
    const Vec3& c = m.vertices_mm[static_cast<size_t>(t[2])];
    const Vec3 n = (b - a).cross(c - a).normalized();
    for (const Vec3& p : {n, a, b, c}) {
      put_f32(p.x());
      put_f32(p.y());
      put_f32(p.z());
    }
    s.append(2, '\0');
  }
  return s;
}

/// A hand-written NRRD header (attached raw data follows) for uchar samples.
inline std::string nrrd_header(const Vec3i& sizes, const std::string& space, const Mat3& directions,
                               const Vec3& origin, const std::string& encoding = "raw") {
  std::string s = "NRRD0004\ntype: uchar\ndimension: 3\nspace: " + space + "\nsizes: " + std::to_string(sizes.x()) +
                  " " + std::to_string(sizes.y()) + " " + std::to_string(sizes.z()) + "\nspace directions:";
  for (int a = 0; a < 3; ++a)
    s += " (" + std::to_string(directions(0, a)) + "," + std::to_string(directions(1, a)) + "," +
         std::to_string(directions(2, a)) + ")";
  s += "\nkinds: space space space\nendian: little\nencoding: " + encoding + "\nspace origin: (" +
       std::to_string(origin.x()) + "," + std::to_string(origin.y()) + "," + std::to_string(origin.z()) + ")\n\n";
  return s;
}

/// A real-data file the tests need; fails the test (never skips) when it is absent.
inline std::filesystem::path require_real_data(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file))
    ADD_FAILURE() << file.string() << " is missing: run scripts/install-deps.sh (it installs mricron-data and "
                     "libcgal-demo, which provide the real data the io tests load)";
  return file;
}

inline const std::filesystem::path kColin27Head = "/usr/share/mricron/templates/ch2.nii.gz";
inline const std::filesystem::path kCgalData = "/usr/share/doc/libcgal-dev/data.tar.gz";

/// Extracts CGAL's data/meshes/man.off into `folder`; returns its path (empty on failure, with a
/// test failure recorded).
inline std::filesystem::path extract_cgal_man(const std::filesystem::path& folder) {
  if (require_real_data(kCgalData).empty() || !std::filesystem::exists(kCgalData)) return {};
  const std::string command = "tar -xzf '" + kCgalData.string() + "' -C '" + folder.string() + "' data/meshes/man.off";
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "could not extract data/meshes/man.off from " << kCgalData << ": run scripts/install-deps.sh";
    return {};
  }
  return folder / "data/meshes/man.off";
}

}  // namespace cleave::test
