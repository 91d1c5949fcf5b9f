// Reading one frame file into a Mesh, whatever its format.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "snag/mesh/mesh.h"

namespace snag::io {

/// Reads a frame file. The extension picks the reader, case-insensitively: `.obj` and `.ply`
/// go to snag's own readers (ids are the file's, 0-based, file order); any other extension
/// goes through assimp with identical vertices joined and polygons triangulated, and the mesh
/// says so (`ids_from_assimp`). Throws snag::InputError naming the file, the line or byte
/// offset, what was found and what was expected.
mesh::Mesh read_mesh(const std::filesystem::path& path);

namespace detail {
struct StructureCache;
}

/// Reads the frames of a sequence one after another, as read_mesh does, parsing in full only
/// what changes. A simulator rewrites positions and nothing else, so a frame whose bytes past
/// its vertices (its faces, polygons and groups) are those of the last frame this reader
/// parsed in full, under the same PLY header, has only its positions parsed and takes that
/// frame's structure: a memcmp where faces were parsed. Any difference is parsed in full, so
/// results and errors are read_mesh's, whatever the files. One reader per thread.
class FrameReader {
 public:
  FrameReader();
  ~FrameReader();
  FrameReader(FrameReader&&) noexcept;
  FrameReader& operator=(FrameReader&&) noexcept;

  mesh::Mesh read(const std::filesystem::path& path);

  /// Frames that took their structure from an earlier frame instead of parsing it.
  int64_t frames_reused() const;

 private:
  std::unique_ptr<detail::StructureCache> cache_;
};

/// The file name's extension with ASCII letters lowered (".OBJ" -> ".obj"; "" when none): what
/// picks a frame file's reader, and what a sequence's kinds of file are told apart by.
std::string lowercase_extension(const std::filesystem::path& path);

/// The whole file in one read (the readers parse from memory). Throws snag::InputError when the
/// file cannot be opened or read.
std::string read_file_bytes(const std::filesystem::path& path);

}  // namespace snag::io
