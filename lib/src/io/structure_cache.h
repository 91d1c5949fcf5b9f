// What a frame file holds besides its vertex positions, remembered from the last frame parsed
// in full, so that a later frame whose bytes past its vertices are the same is not parsed
// again (io::FrameReader). Private to lib/src/io.
//
// The rule that makes reuse exact: a reader's output is a function of the bytes it parses and
// of its state where it starts them. Both readers read vertices before faces in the files this
// applies to, so a file splits into
//
//   prefix | vertex block | tail
//
// where the prefix is what must match for the vertex block to mean the same (PLY: the header,
// with its element counts and types; OBJ: nothing, the parser's state at the tail is compared
// instead), and the tail holds every face, polygon and group. Equal prefix, equal state at the
// tail's start and equal tail bytes give the same faces, polygons and groups; only the
// positions are parsed. Any difference, or a file laid out otherwise (an OBJ face before a
// vertex, a PLY face element before the vertex element), is parsed in full as usual.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

#include "snag/mesh/mesh.h"

namespace snag::io::detail {

struct StructureCache {
  bool valid = false;
  std::string prefix;          ///< PLY: the header's bytes; OBJ: empty
  std::string tail;            ///< the bytes after the vertex block, to the end of the file
  int64_t vertex_count = 0;    ///< vertices before the tail
  std::string state;           ///< OBJ: the group name pending at the tail's start, if any
  bool state_pending = false;  ///< OBJ: whether a group name is pending there
  mesh::Mesh structure;        ///< everything but the positions (which stay empty)
  int64_t reused = 0;          ///< frames that took their structure from here

  /// True when the rest of a file, `tail`, after `vertex_count` vertices parsed under
  /// `prefix` and OBJ state (`state_pending`, `state`), is the remembered one.
  bool matches(std::string_view file_prefix, int64_t vertices, bool pending,
               std::string_view pending_name, const char* rest, const char* end) const {
    return valid && static_cast<size_t>(end - rest) == tail.size() && vertices == vertex_count &&
           pending == state_pending && (!pending || pending_name == state) &&
           file_prefix == prefix && std::memcmp(rest, tail.data(), tail.size()) == 0;
  }

  /// Gives `mesh` (its positions parsed) the remembered structure.
  void apply(mesh::Mesh& mesh) {
    mesh.triangles = structure.triangles;
    mesh.source_polygon = structure.source_polygon;
    mesh.triangle_group = structure.triangle_group;
    mesh.group_names = structure.group_names;
    mesh.polygon_count = structure.polygon_count;
    ++reused;
  }

  /// Remembers a file parsed in full. `rest` is where its tail starts.
  void store(std::string_view file_prefix, bool pending, std::string_view pending_name,
             const char* rest, const char* end, const mesh::Mesh& mesh) {
    valid = true;
    prefix.assign(file_prefix);
    tail.assign(rest, end);
    vertex_count = static_cast<int64_t>(mesh.positions.size());
    state_pending = pending;
    state.assign(pending ? pending_name : std::string_view());
    structure.triangles = mesh.triangles;
    structure.source_polygon = mesh.source_polygon;
    structure.triangle_group = mesh.triangle_group;
    structure.group_names = mesh.group_names;
    structure.polygon_count = mesh.polygon_count;
  }

  /// Forgets the remembered file (one that cannot be reused, or one that failed).
  void clear() { valid = false; }
};

/// read_obj and read_ply, reusing `cache`'s structure when the file allows it and remembering
/// this file's structure in `cache` when parsed in full. Same results and errors as those.
mesh::Mesh read_obj_reusing(std::string_view text, const std::string& name_for_errors,
                            StructureCache& cache);
mesh::Mesh read_ply_reusing(std::string_view bytes, const std::string& name_for_errors,
                            StructureCache& cache);

}  // namespace snag::io::detail
