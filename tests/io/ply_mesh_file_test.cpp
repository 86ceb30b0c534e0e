// cleave's own PLY mesh reader (io/ply_mesh_file): the three encodings give the same mesh, every
// scalar type is decoded, polygons are fan-triangulated, and every malformed body gets one named
// error. (assimp read PLY before and corrupted the heap on malformed files under fuzzing.)
#include <bit>
#include <cstdint>
#include <functional>
#include <gtest/gtest.h>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/io/ply_mesh_file.hpp"
#include "cleave/io/surface_mesh_file.hpp"
#include "io_fixtures.hpp"

namespace cleave {
namespace {

using test::input_error_of;

/// Appends `value` as `bytes` bytes, little- or big-endian.
void put(std::string& out, std::uint64_t value, std::size_t bytes, bool big_endian) {
  for (std::size_t k = 0; k < bytes; ++k)
    out += static_cast<char>((value >> (8 * (big_endian ? bytes - 1 - k : k))) & 0xff);
}

/// A unit square (0,0,0) (1,0,0) (1,1,0) (0,1,0) as one quad plus a line (2 corners), with an
/// extra "confidence" vertex property and an extra "edge" element, in the given encoding:
/// x float, y double, z short, then a face list "uchar int".
std::string square_ply(const std::string& format) {
  std::string text = "ply\nformat " + format +
                     " 1.0\ncomment made by the test\nelement vertex 4\nproperty float x\nproperty double y\n"
                     "property short z\nproperty uchar confidence\nelement face 2\nproperty list uchar int vertex_indices\n"
                     "property float quality\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  const double xs[4] = {0, 1, 1, 0}, ys[4] = {0, 0, 1, 1};
  if (format == "ascii") {
    for (int v = 0; v < 4; ++v) text += std::to_string(xs[v]) + " " + std::to_string(ys[v]) + " 0 255\n";
    return text + "4 0 1 2 3 0.5\n2 0 2 1\n0 2\n";
  }
  const bool be = format == "binary_big_endian";
  for (int v = 0; v < 4; ++v) {
    put(text, std::bit_cast<std::uint32_t>(static_cast<float>(xs[v])), 4, be);
    put(text, std::bit_cast<std::uint64_t>(ys[v]), 8, be);
    put(text, 0, 2, be);
    put(text, 255, 1, be);
  }
  put(text, 4, 1, be);
  for (int c : {0, 1, 2, 3}) put(text, static_cast<std::uint64_t>(c), 4, be);
  put(text, std::bit_cast<std::uint32_t>(0.5f), 4, be);
  put(text, 2, 1, be);
  for (int c : {0, 2}) put(text, static_cast<std::uint64_t>(c), 4, be);
  put(text, std::bit_cast<std::uint32_t>(1.0f), 4, be);
  put(text, 0, 4, be);
  put(text, 2, 4, be);
  return text;
}

TEST(PlyMeshFile, TheThreeEncodingsGiveTheSameFanTriangulatedMesh) {
  test::TempFolder tmp;
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    test::write_bytes(tmp / "square.ply", square_ply(format));
    const TriangleMesh mesh = read_ply_mesh(tmp / "square.ply", 10.0);
    ASSERT_EQ(mesh.vertices_mm.size(), 4u);
    EXPECT_EQ(mesh.vertices_mm[2], Vec3(10, 10, 0));
    EXPECT_EQ(mesh.vertices_mm[3], Vec3(0, 10, 0));
    // the quad becomes the fan (0 1 2) (0 2 3); the two-corner face is a line and is dropped
    ASSERT_EQ(mesh.triangles.size(), 2u);
    EXPECT_EQ(mesh.triangles[0], (std::array<int, 3>{0, 1, 2}));
    EXPECT_EQ(mesh.triangles[1], (std::array<int, 3>{0, 2, 3}));
  }
}

TEST(PlyMeshFile, SignedAndUnsignedIntegersOfEveryWidthAreDecoded) {
  test::TempFolder tmp;
  for (const bool be : {false, true}) {
    std::string text = std::string("ply\nformat ") + (be ? "binary_big_endian" : "binary_little_endian") +
                       " 1.0\nelement vertex 3\nproperty char x\nproperty int16 y\nproperty int z\n"
                       "element face 1\nproperty list char ushort vertex_index\nend_header\n";
    const std::int64_t xs[3] = {-128, 127, 0}, ys[3] = {-32768, 0, 32767}, zs[3] = {-2147483647 - 1, 5, 2147483647};
    for (int v = 0; v < 3; ++v) {
      put(text, static_cast<std::uint64_t>(xs[v]), 1, be);
      put(text, static_cast<std::uint64_t>(ys[v]), 2, be);
      put(text, static_cast<std::uint64_t>(zs[v]), 4, be);
    }
    put(text, 3, 1, be);
    for (int c : {2, 1, 0}) put(text, static_cast<std::uint64_t>(c), 2, be);
    test::write_bytes(tmp / "ints.ply", text);
    const TriangleMesh mesh = read_ply_mesh(tmp / "ints.ply", 1.0);
    ASSERT_EQ(mesh.vertices_mm.size(), 3u);
    EXPECT_EQ(mesh.vertices_mm[0], Vec3(-128, -32768, -2147483648.0));
    EXPECT_EQ(mesh.vertices_mm[2], Vec3(0, 32767, 2147483647.0));
    ASSERT_EQ(mesh.triangles.size(), 1u);
    EXPECT_EQ(mesh.triangles[0], (std::array<int, 3>{2, 1, 0}));
  }
}

TEST(PlyMeshFile, MalformedBodiesGetOneNamedError) {
  test::TempFolder tmp;
  const std::string p = (tmp / "m.ply").string();
  const auto error_for = [&](const std::string& bytes) {
    test::write_bytes(tmp / "m.ply", bytes);
    return input_error_of([&] { (void)read_surface_mesh(tmp / "m.ply", 1.0); });
  };
  const std::string le = square_ply("binary_little_endian");
  EXPECT_EQ(error_for(le.substr(0, le.size() - 3)),
            p + ": the binary data ends at byte " + std::to_string(le.size() - 3) +
                " while reading element 'edge' 0 of 1 (truncated?)");
  const std::string tri_header =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list int uint vertex_indices\nend_header\n";
  std::string body;
  for (int k = 0; k < 9; ++k) put(body, std::bit_cast<std::uint32_t>(k == 4 ? 1.0f : 0.0f), 4, false);
  std::string nan_body = body;
  nan_body.replace(8, 4, std::string("\x00\x00\xc0\x7f", 4));
  std::string face;
  put(face, 3, 4, false);
  for (int c : {0, 1, 3}) put(face, static_cast<std::uint64_t>(c), 4, false);
  const std::string head = "ply\nformat binary_little_endian 1.0\n" + tri_header;
  EXPECT_EQ(error_for(head + body + face), p + ": element 'face' 0 refers to vertex 3; the file has 3 vertices");
  std::string negative_count;
  put(negative_count, 0xffffffff, 4, false);
  EXPECT_EQ(error_for(head + body + negative_count),
            p + ": the binary data ends at byte " + std::to_string(head.size() + body.size() + 4) +
                " while reading element 'face' 0 of 1 (truncated?)");
  EXPECT_EQ(error_for(head + nan_body + face), p + ": vertex 0 is (0, 0, nan); expected finite coordinates");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 0 0\n"),
            p + ": the PLY file has no 'vertex' element; expected one with properties x, y and z");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"),
            p + ": PLY element 'vertex' has no scalar property 'z'; expected x, y and z");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\n" + tri_header + "0 0 0\n0 1 0\n"),
            p + ": the ASCII data ends while reading element 'vertex' 2 of 3 (truncated?)");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\n" + tri_header + "0 0 0\n0 1 0\n1 0\n3 0 1 2\n"),
            p + ": element 'vertex' 2 has fewer values than its 3 properties");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\n" + tri_header + "0 0 0\n0 1 0\n1 0 0\n3 0 1      \n"),
            p + ": element 'face' 0 has a list of 3 items but fewer values");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\n" + tri_header + "0 0 0\n0 1 0\n1 0 0\n2 0 1\n"),
            p + ": the mesh has no triangles");
}

}  // namespace
}  // namespace cleave
