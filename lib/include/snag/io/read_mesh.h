// Reading one frame file into a Mesh, whatever its format.
#pragma once

#include <filesystem>
#include <string>

#include "snag/mesh/mesh.h"

namespace snag::io {

/// Reads a frame file. The extension picks the reader, case-insensitively: `.obj` and `.ply`
/// go to snag's own readers (ids are the file's, 0-based, file order); any other extension
/// goes through assimp with identical vertices joined and polygons triangulated, and the mesh
/// says so (`ids_from_assimp`). Throws snag::InputError naming the file, the line or byte
/// offset, what was found and what was expected.
mesh::Mesh read_mesh(const std::filesystem::path& path);

/// The whole file in one read (the readers parse from memory). Throws snag::InputError when the
/// file cannot be opened or read.
std::string read_file_bytes(const std::filesystem::path& path);

}  // namespace snag::io
