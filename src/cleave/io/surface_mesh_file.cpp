#include "cleave/io/surface_mesh_file.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/io/off_mesh_file.hpp"
#include "cleave/io/ply_mesh_file.hpp"

namespace cleave {
namespace {

[[noreturn]] void fail_import(const std::string& file, std::string why) {
  while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
  throw InputError(fmt::format("{}: cannot read the mesh: {}", file, why.empty() ? "unknown format" : why));
}

}  // namespace

TriangleMesh read_surface_mesh(const std::filesystem::path& file, double scale) {
  const std::string f = file.string();
  if (!(scale > 0) || !std::isfinite(scale))
    throw InputError(fmt::format("{}: mesh scale {}; expected a positive finite factor", f, scale));
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such file", f));

  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // OFF and PLY are parsed by cleave: assimp's OFF importer aborts on truncated files and its PLY
  // importer corrupted the heap on malformed ones (off_mesh_file.hpp, ply_mesh_file.hpp).
  if (extension == ".off" || extension == ".ply") {
    TriangleMesh mesh = extension == ".off" ? read_off_mesh(file, scale) : read_ply_mesh(file, scale);
    if (mesh.triangles.empty()) throw InputError(fmt::format("{}: the mesh has no triangles", f));
    for (const Vec3& p : mesh.vertices_mm)
      if (!p.allFinite())
        throw InputError(fmt::format("{}: mesh scale {} makes coordinates overflow; expected a smaller scale", f, scale));
    return mesh;
  }

  Assimp::Importer importer;
  // Keep points and lines out (only triangles bound a volume); no normals or UVs are needed.
  // Per-face normals (STL) and other attributes would keep identical positions apart when joining.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_COLORS | aiComponent_TEXCOORDS);
  // Import first, check the faces, then post-process: assimp's importers can produce a face
  // with no corners from a malformed file (ASCII PLY with garbage in a face line), which
  // ValidateDataStructure lets through and Triangulate / SortByPType then abort or crash on
  // (found by fuzz_mesh_ply).
  const aiScene* raw = importer.ReadFile(f, aiProcess_ValidateDataStructure);
  if (raw == nullptr) fail_import(f, importer.GetErrorString());
  for (unsigned m = 0; m < raw->mNumMeshes; ++m) {
    const aiMesh& part = *raw->mMeshes[m];
    for (unsigned t = 0; t < part.mNumFaces; ++t) {
      const aiFace& face = part.mFaces[t];
      if (face.mNumIndices == 0 || face.mIndices == nullptr)
        fail_import(f, fmt::format("face {} has no vertices (malformed face)", t));
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= part.mNumVertices)
          fail_import(f, fmt::format("face {} refers to vertex {}; the mesh has {} vertices", t, face.mIndices[k], part.mNumVertices));
    }
  }
  const aiScene* scene = importer.ApplyPostProcessing(aiProcess_RemoveComponent | aiProcess_Triangulate |
                                                      aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                                                      aiProcess_SortByPType);
  if (scene == nullptr) fail_import(f, importer.GetErrorString());
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    const size_t base = mesh.vertices_mm.size();
    if (base + part.mNumVertices > static_cast<size_t>(std::numeric_limits<int>::max()))
      throw InputError(fmt::format("{}: more than 2^31 vertices", f));
    for (unsigned v = 0; v < part.mNumVertices; ++v) {
      const aiVector3D& p = part.mVertices[v];
      const Vec3 position(static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z));
      if (!position.allFinite())
        throw InputError(fmt::format("{}: vertex {} is ({}, {}, {}); expected finite coordinates", f,
                                     mesh.vertices_mm.size(), position.x(), position.y(), position.z()));
      mesh.vertices_mm.push_back(scale * position);
    }
    for (unsigned t = 0; t < part.mNumFaces; ++t) {
      const aiFace& face = part.mFaces[t];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({static_cast<int>(base + face.mIndices[0]), static_cast<int>(base + face.mIndices[1]),
                                static_cast<int>(base + face.mIndices[2])});
    }
  }
  if (mesh.triangles.empty()) throw InputError(fmt::format("{}: the mesh has no triangles", f));
  for (const Vec3& p : mesh.vertices_mm)
    if (!p.allFinite())
      throw InputError(fmt::format("{}: mesh scale {} makes coordinates overflow; expected a smaller scale", f, scale));
  return mesh;
}

}  // namespace cleave
