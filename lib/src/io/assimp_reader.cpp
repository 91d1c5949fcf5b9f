// Formats other than OBJ and PLY through assimp. assimp renumbers and splits vertices, so the
// ids of these meshes are assimp's; the mesh says so and the reports repeat it.
#include "snag/io/assimp_reader.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <limits>

#include "snag/error.h"

namespace snag::io {
namespace {

struct SceneFlattener {
  const aiScene* scene;
  const std::string& name;
  mesh::Mesh out;

  void add_node(const aiNode* node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 world = parent * node->mTransformation;
    for (unsigned k = 0; k < node->mNumMeshes; ++k)
      add_mesh(*scene->mMeshes[node->mMeshes[k]], world);
    for (unsigned c = 0; c < node->mNumChildren; ++c) add_node(node->mChildren[c], world);
  }

  void add_mesh(const aiMesh& m, const aiMatrix4x4& world) {
    const int64_t base = static_cast<int64_t>(out.positions.size());
    if (base + m.mNumVertices > std::numeric_limits<int32_t>::max()) {
      throw InputError(name, 0, "scene has more than 2^31-1 vertices");
    }
    for (unsigned i = 0; i < m.mNumVertices; ++i) {
      const aiVector3D p = world * m.mVertices[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw InputError(name, 0,
                         "vertex " + std::to_string(base + i) +
                             " (assimp's numbering) has a NaN or infinite coordinate");
      }
      out.positions.push_back({p.x, p.y, p.z});
    }
    const int32_t group = static_cast<int32_t>(out.group_names.size());
    out.group_names.emplace_back(m.mName.C_Str());
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      // Points and lines carry no surface; aiProcess_Triangulate leaves every polygon a triangle.
      if (face.mNumIndices != 3) continue;
      out.source_polygon.push_back(static_cast<int32_t>(out.triangles.size()));
      out.triangles.push_back({{static_cast<int32_t>(base + face.mIndices[0]),
                                static_cast<int32_t>(base + face.mIndices[1]),
                                static_cast<int32_t>(base + face.mIndices[2])}});
      out.triangle_group.push_back(group);
    }
  }
};

}  // namespace

mesh::Mesh read_with_assimp(const std::filesystem::path& path) {
  Assimp::Importer importer;
  // Joining compares every vertex attribute, not only the position: an STL corner carries its
  // facet's normal, so without removing normals (and UVs, colors, tangents, which split
  // vertices on seams the same way) a folded STL would stay a triangle soup.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_TEXCOORDS);
  // Validated first: an importer can hand the steps after it a malformed scene (an OFF file
  // with a face line cut short or missing), on which libassimp 5.2's triangulation asserts
  // (aborting the process) or reads out of bounds; validation turns that into an error.
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_ValidateDataStructure | aiProcess_RemoveComponent |
                         aiProcess_JoinIdenticalVertices | aiProcess_Triangulate);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw InputError(path.string(), 0,
                     std::string("assimp cannot read the file: ") + importer.GetErrorString());
  }
  SceneFlattener flat{scene, path.string(), {}};
  flat.add_node(scene->mRootNode, aiMatrix4x4());
  flat.out.polygon_count = static_cast<int64_t>(flat.out.triangles.size());
  flat.out.ids_from_assimp = true;
  return std::move(flat.out);
}

}  // namespace snag::io
