// Wavefront OBJ reader: positions and faces, with the file's ids.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "snag/mesh/mesh.h"

namespace snag::io {

/// Parses OBJ text held in memory. Accepted: `v x y z` (extra numbers such as w or vertex
/// colors are ignored), `f` corners written `v`, `v/vt`, `v//vn` or `v/vt/vn` with positive
/// (1-based) or negative (relative to the vertices listed so far) indices, `o` and `g` names,
/// comments, blank lines and CRLF line ends. Every other record (`vt`, `vn`, `s`, `usemtl`,
/// `mtllib`, `l`, a simulator's own `ny`/`nv`, ...) is passed over.
///
/// Ids: vertex i is the (i+1)-th `v` line; polygon p is the (p+1)-th `f` line. A polygon of
/// k > 3 corners becomes the fan (c0, c[j], c[j+1]), j = 1..k-2, each triangle's
/// source_polygon being p. triangle_group holds, per triangle, the index into group_names of
/// the last `o`/`g` name seen before its face (-1 before any, or after an empty `g`).
///
/// Throws snag::InputError(name_for_errors, line, ...) quoting the offending token: a
/// coordinate that is not a number or is NaN/Inf, fewer than 3 coordinates, an index that is
/// 0, not an integer or out of range, a face with fewer than 3 corners.
mesh::Mesh read_obj(std::string_view text, const std::string& name_for_errors);

/// Reads and parses an OBJ file.
mesh::Mesh read_obj_file(const std::filesystem::path& path);

}  // namespace snag::io
