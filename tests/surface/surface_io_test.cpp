// PLY and glTF output of the render surface: round trips, accessor counts and bounds, bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <cstring>
#include <fmt/format.h>
#include <limits>
#include <nlohmann/json.hpp>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/gltf_writer.hpp"
#include "cleave/io/ply_reader.hpp"
#include "cleave/io/ply_writer.hpp"
#include "cleave/surface/surface_mesh.hpp"
#include "surface_test_models.hpp"

namespace cleave {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cleave_surface_test_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The tube's surface, deformed by a shear, with a per-vertex "depth" and colours.
SurfaceMesh sample_mesh() {
  const TissueModel model = test::builtin_model("cylinder");
  const RenderSurface s = build_render_surface(model);
  std::vector<Vec3> u(static_cast<size_t>(model.volume.vertex_count()));
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
    u[static_cast<size_t>(v)] = Vec3(0.05 * model.volume.vertex_position_mm(v).z(), 0, 0);
  SurfaceMesh mesh = make_surface_mesh(s, deformed_positions(s, model.volume, u));
  std::vector<float> depth(mesh.positions_mm.size());
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = static_cast<float>(mesh.positions_mm[i].z() / 104.0);
  attach_vertex_scalars(mesh, "depth", depth);
  mesh.vertex_colors = blue_to_red_colors(depth, 0.0f, 1.0f);
  return mesh;
}

TEST(SurfaceIo, PlyRoundTripKeepsCountsPositionsNormalsAndArrays) {
  const SurfaceMesh mesh = sample_mesh();
  const auto file = temp_dir("ply") / "surface.ply";
  write_ply(file, mesh);
  const SurfaceMesh back = read_ply(file);
  ASSERT_EQ(back.positions_mm.size(), mesh.positions_mm.size());
  ASSERT_EQ(back.triangles, mesh.triangles);
  ASSERT_EQ(back.normals.size(), mesh.normals.size());
  for (size_t i = 0; i < mesh.positions_mm.size(); ++i) {
    EXPECT_EQ(back.positions_mm[i], mesh.positions_mm[i].cast<float>().cast<double>());
    EXPECT_EQ(back.normals[i], mesh.normals[i].cast<float>().cast<double>());
    EXPECT_NEAR((back.vertex_colors[i] - mesh.vertex_colors[i]).cwiseAbs().maxCoeff(), 0.0f, 0.51f / 255.0f);
  }
  ASSERT_EQ(back.vertex_scalars.size(), 1u);
  EXPECT_EQ(back.vertex_scalars[0].name, "depth");
  EXPECT_EQ(back.vertex_scalars[0].values, mesh.vertex_scalars[0].values);
  ASSERT_EQ(back.triangle_scalars.size(), 2u);
  EXPECT_EQ(back.triangle_scalars[0].name, "is_cut");
  EXPECT_EQ(back.triangle_scalars[1].name, "cell");
  EXPECT_EQ(back.triangle_scalars[1].values, mesh.triangle_scalars[1].values);
}

TEST(SurfaceIo, PlyReaderNamesTheFileAndTheProblem) {
  const auto dir = temp_dir("ply_bad");
  EXPECT_THROW(read_ply(dir / "missing.ply"), InputError);
  write_file_atomically(dir / "text.ply", "solid cube\n");
  try {
    read_ply(dir / "text.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("text.ply: not a PLY file"), std::string::npos) << e.what();
  }
  write_ply(dir / "whole.ply", sample_mesh());
  std::string bytes = read_file(dir / "whole.ply");
  write_file_atomically(dir / "truncated.ply", bytes.substr(0, bytes.size() - 100));
  try {
    read_ply(dir / "truncated.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated.ply: the data ends early"), std::string::npos) << e.what();
  }
}

std::string base64_decode(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::uint32_t block = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=') break;
    block = (block << 6) | static_cast<std::uint32_t>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((block >> bits) & 0xFFu);
    }
  }
  return out;
}

TEST(SurfaceIo, GltfAccessorsHaveTheRightCountsBoundsAndData) {
  const SurfaceMesh mesh = sample_mesh();
  const auto file = temp_dir("gltf") / "surface.gltf";
  write_gltf(file, mesh);
  const nlohmann::json gltf = nlohmann::json::parse(read_file(file));
  EXPECT_EQ(gltf["asset"]["version"], "2.0");
  const auto& primitive = gltf["meshes"][0]["primitives"][0];
  EXPECT_EQ(primitive["mode"], 4);
  const auto& accessors = gltf["accessors"];
  const auto& position = accessors[primitive["attributes"]["POSITION"].get<size_t>()];
  EXPECT_EQ(position["count"], mesh.positions_mm.size());
  EXPECT_EQ(position["type"], "VEC3");
  Vec3f lo = Vec3f::Constant(1e30f), hi = Vec3f::Constant(-1e30f);
  for (const Vec3& p : mesh.positions_mm) {
    lo = lo.cwiseMin(p.cast<float>());
    hi = hi.cwiseMax(p.cast<float>());
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(position["min"][static_cast<size_t>(a)].get<float>(), lo[a]);
    EXPECT_EQ(position["max"][static_cast<size_t>(a)].get<float>(), hi[a]);
  }
  EXPECT_EQ(accessors[primitive["attributes"]["NORMAL"].get<size_t>()]["count"], mesh.positions_mm.size());
  EXPECT_EQ(accessors[primitive["attributes"]["COLOR_0"].get<size_t>()]["count"], mesh.positions_mm.size());
  EXPECT_EQ(accessors[primitive["attributes"]["_DEPTH"].get<size_t>()]["count"], mesh.positions_mm.size());
  const auto& indices = accessors[primitive["indices"].get<size_t>()];
  EXPECT_EQ(indices["count"], 3 * mesh.triangles.size());
  EXPECT_EQ(indices["componentType"], 5125);

  // The embedded buffer holds exactly the float positions and the triangle indices.
  const std::string uri = gltf["buffers"][0]["uri"];
  const std::string prefix = "data:application/octet-stream;base64,";
  ASSERT_EQ(uri.rfind(prefix, 0), 0u);
  const std::string bytes = base64_decode(uri.substr(prefix.size()));
  ASSERT_EQ(bytes.size(), gltf["buffers"][0]["byteLength"].get<size_t>());
  const auto& view = gltf["bufferViews"][position["bufferView"].get<size_t>()];
  for (size_t i = 0; i < mesh.positions_mm.size(); i += 97) {
    float p[3];
    std::memcpy(p, bytes.data() + view["byteOffset"].get<size_t>() + 12 * i, 12);
    EXPECT_EQ(Vec3f(p[0], p[1], p[2]), mesh.positions_mm[i].cast<float>());
  }
  const auto& index_view = gltf["bufferViews"][indices["bufferView"].get<size_t>()];
  for (size_t t = 0; t < mesh.triangles.size(); t += 101) {
    std::uint32_t v[3];
    std::memcpy(v, bytes.data() + index_view["byteOffset"].get<size_t>() + 12 * t, 12);
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(static_cast<std::int32_t>(v[k]), mesh.triangles[t][k]);
  }
}

TEST(SurfaceIo, AttachedArraysAreChecked) {
  SurfaceMesh mesh = sample_mesh();
  try {
    attach_vertex_scalars(mesh, "traction_kPa", std::vector<float>(3, 1.0f));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("surface vertex array 'traction_kPa' has 3 values; expected {}", mesh.positions_mm.size()));
  }
  EXPECT_THROW(attach_triangle_scalars(mesh, "bad name", std::vector<float>(mesh.triangles.size())), InputError);
  std::vector<float> with_nan(mesh.triangles.size(), 0.0f);
  with_nan[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(attach_triangle_scalars(mesh, "depth", with_nan), InputError);
  // NaN marks triangles to leave out when spreading to vertices; others average by area.
  const std::vector<float> per_vertex = triangle_to_vertex_scalars(mesh, std::vector<float>(mesh.triangles.size(), 2.5f));
  for (float v : per_vertex) EXPECT_FLOAT_EQ(v, 2.5f);
}

}  // namespace
}  // namespace cleave
