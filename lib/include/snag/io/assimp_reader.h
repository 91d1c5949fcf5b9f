// Every format other than OBJ and PLY, through assimp.
#pragma once

#include <filesystem>
#include <string>

#include "snag/mesh/mesh.h"

struct aiScene;

namespace snag::io {

/// Imports a file with assimp: normals, UVs, colors and tangents dropped so that vertices at
/// one position are joined (an STL triangle soup comes back welded), polygons triangulated. All
/// meshes of the scene are concatenated in node order, each placed by its node's world transform;
/// every triangle's group is its mesh's name. Ids are assimp's, not the file's: `ids_from_assimp`
/// is true and source_polygon is the triangle's own index. Throws snag::InputError with assimp's
/// message.
mesh::Mesh read_with_assimp(const std::filesystem::path& path);

/// Why assimp's scene as read (before its post-processing steps) is not sound, or empty when it
/// is: a face without corners, or a corner past its mesh's vertices. libassimp 5.2 reads some
/// valid files wrongly (a binary PLY whose data starts with a byte that looks like whitespace is
/// read one byte off: faces without corners), and its post-processing steps then abort the
/// process or read out of bounds; so a scene is read without steps, checked, then processed.
std::string unsound_assimp_scene(const aiScene& scene);

}  // namespace snag::io
