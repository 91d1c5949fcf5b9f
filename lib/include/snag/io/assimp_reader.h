// Every format other than OBJ and PLY, through assimp.
#pragma once

#include <filesystem>

#include "snag/mesh/mesh.h"

namespace snag::io {

/// Imports a file with assimp: normals, UVs, colors and tangents dropped so that vertices at
/// one position are joined (an STL triangle soup comes back welded), polygons triangulated. All
/// meshes of the scene are concatenated in node order, each placed by its node's world transform;
/// every triangle's group is its mesh's name. Ids are assimp's, not the file's: `ids_from_assimp`
/// is true and source_polygon is the triangle's own index. Throws snag::InputError with assimp's
/// message.
mesh::Mesh read_with_assimp(const std::filesystem::path& path);

}  // namespace snag::io
