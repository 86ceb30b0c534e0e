#include "cleave/io/surface_mesh_file.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/io/off_mesh_file.hpp"

namespace cleave {

SurfaceMesh read_surface_mesh(const std::filesystem::path& file, double scale) {
  const std::string f = file.string();
  if (!(scale > 0) || !std::isfinite(scale))
    throw InputError(fmt::format("{}: mesh scale {}; expected a positive finite factor", f, scale));
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such file", f));

  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".off") {
    SurfaceMesh mesh = read_off_mesh(file, scale);
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
  const aiScene* scene =
      importer.ReadFile(f, aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                               aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (scene == nullptr) {
    std::string why = importer.GetErrorString();
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
    throw InputError(fmt::format("{}: cannot read the mesh: {}", f, why.empty() ? "unknown format" : why));
  }
  SurfaceMesh mesh;
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
