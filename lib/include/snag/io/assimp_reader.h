// Every format other than OBJ and PLY, through assimp.
#pragma once

#include <filesystem>
#include <string>

#include "snag/mesh/mesh.h"

struct aiScene;
namespace Assimp {
class Importer;
}

namespace snag::io {

/// Imports a file with assimp: normals, UVs, colors and tangents dropped so that vertices at
/// one position are joined (an STL triangle soup comes back welded), polygons triangulated. All
/// meshes of the scene are concatenated in node order, each placed by its node's world transform;
/// every triangle's group is its mesh's name. Ids are assimp's, not the file's: `ids_from_assimp`
/// is true and source_polygon is the triangle's own index. Throws snag::InputError with assimp's
/// message.
mesh::Mesh read_with_assimp(const std::filesystem::path& path);

/// Reads `path` with `importer` and only the steps `reading` (validation, say), checks every
/// face of the scene (at least one corner, each within its mesh's vertices), then applies the
/// post-processing `steps`; the scene lives as long as the importer. libassimp 5.2 reads some
/// valid files wrongly (a binary PLY whose data starts with a byte that looks like whitespace
/// is read one byte off: faces without corners), and its post-processing steps then abort the
/// process or read out of bounds: checked first, such a scene is a snag::InputError naming the
/// file, as is one assimp cannot read or process.
const aiScene& import_checked(Assimp::Importer& importer, const std::filesystem::path& path,
                              unsigned reading, unsigned steps);

}  // namespace snag::io
