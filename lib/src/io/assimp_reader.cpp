// Formats other than OBJ and PLY through assimp. assimp renumbers and splits vertices, so the
// ids of these meshes are assimp's; the mesh says so and the reports repeat it.
#include "snag/io/assimp_reader.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>

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

/// An OFF file's declared counts against its size, before assimp reserves room for them:
/// libassimp 5.2's OFF importer allocates what the header says (a 45-byte file declaring a
/// billion vertices took 12 GB, then aborted the process). Every vertex line takes at least 6
/// bytes ("0 0 0\n"), every face line 2 ("0\n"). Headers this does not recognise (the 4OFF and
/// nOFF variants, counts past the first 4 KB) are left to assimp.
void check_off_counts(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  // Whitespace-separated words, '#' comments left out.
  size_t at = 0;
  auto next_word = [&]() -> std::string_view {
    for (;;) {
      while (at < head.size() && std::isspace(static_cast<unsigned char>(head[at]))) ++at;
      if (at < head.size() && head[at] == '#') {
        while (at < head.size() && head[at] != '\n') ++at;
        continue;
      }
      const size_t begin = at;
      while (at < head.size() && !std::isspace(static_cast<unsigned char>(head[at]))) ++at;
      return std::string_view(head).substr(begin, at - begin);
    }
  };
  const std::string_view keyword = next_word();
  if (!keyword.ends_with("OFF") || keyword.find_first_of("4n") != std::string_view::npos) return;
  uint64_t counts[2] = {};
  for (uint64_t& count : counts) {
    const std::string_view word = next_word();
    if (at >= head.size() && head.size() == 4096) return;  // cut off by the 4 KB: left
    if (std::from_chars(word.data(), word.data() + word.size(), count).ec != std::errc()) return;
  }
  std::error_code error;
  const uintmax_t size = std::filesystem::file_size(path, error);
  if (error) return;
  const auto [vertices, faces] = counts;
  if (vertices > size / 6 || faces > size / 2 || 6 * vertices + 2 * faces > size)
    throw InputError(path.string(), 0,
                     "its header declares " + std::to_string(vertices) +
                         (vertices == 1 ? " vertex and " : " vertices and ") +
                         std::to_string(faces) + (faces == 1 ? " face" : " faces") +
                         ", more than its " + std::to_string(size) + " bytes can hold");
}

/// Why assimp's scene as read (before its post-processing steps) is not sound, or empty when it
/// is: a face without corners, or a corner past its mesh's vertices.
std::string unsound_assimp_scene(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr) return "mesh " + std::to_string(m) + " is missing";
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      const std::string which =
          "face " + std::to_string(f) + " of mesh " + std::to_string(m) + " (assimp's numbering)";
      if (face.mNumIndices == 0 || face.mIndices == nullptr) return which + " has no corners";
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh->mNumVertices)
          return which + " has corner " + std::to_string(face.mIndices[k]) + " of " +
                 std::to_string(mesh->mNumVertices) + " vertices";
    }
  }
  return {};
}

}  // namespace

const aiScene& import_checked(Assimp::Importer& importer, const std::filesystem::path& path,
                              unsigned reading, unsigned steps) {
  const aiScene* scene = importer.ReadFile(path.string(), reading);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw InputError(path.string(), 0,
                     std::string("assimp cannot read the file: ") + importer.GetErrorString());
  }
  if (const std::string unsound = unsound_assimp_scene(*scene); !unsound.empty())
    throw InputError(path.string(), 0, "assimp read the file wrongly or it is corrupt: " + unsound);
  scene = importer.ApplyPostProcessing(steps);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw InputError(path.string(), 0,
                     std::string("assimp cannot process the file: ") + importer.GetErrorString());
  }
  return *scene;
}

mesh::Mesh read_with_assimp(const std::filesystem::path& path) {
  Assimp::Importer importer;
  // Joining compares every vertex attribute, not only the position: an STL corner carries its
  // facet's normal, so without removing normals (and UVs, colors, tangents, which split
  // vertices on seams the same way) a folded STL would stay a triangle soup.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_TEXCOORDS);
  const unsigned steps =
      aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices | aiProcess_Triangulate;
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  unsigned reading = 0;
  if (extension == ".off") {
    check_off_counts(path);
    // libassimp 5.2's OFF importer hands on a face without indices when a face line is missing
    // or unreadable; its validation refuses it. Only for OFF: it checks the whole scene, and
    // refuses files of other formats whose cameras or lights share a name (which FBX allows)
    // though their meshes are sound.
    reading = aiProcess_ValidateDataStructure;
  }
  const aiScene& scene = import_checked(importer, path, reading, steps);
  SceneFlattener flat{&scene, path.string(), {}};
  flat.add_node(scene.mRootNode, aiMatrix4x4());
  flat.out.polygon_count = static_cast<int64_t>(flat.out.triangles.size());
  flat.out.ids_from_assimp = true;
  return std::move(flat.out);
}

}  // namespace snag::io
