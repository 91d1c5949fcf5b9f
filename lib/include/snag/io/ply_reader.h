// Stanford PLY reader (ascii, binary little- and big-endian), with the file's ids.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "snag/mesh/mesh.h"

namespace snag::io {

/// Parses a PLY file held in memory (`bytes` is the whole file, header and body).
///
/// The `vertex` element must have `x`, `y` and `z` properties of any scalar type (char, uchar,
/// short, ushort, int, uint, float, double or their int8 ... float64 names); its other
/// properties are skipped. The `face` element must have a list property `vertex_indices` or
/// `vertex_index` with any integer count and index types; its other properties, and every other
/// element (edge, material, ...), are skipped in all three encodings.
///
/// Ids: vertex i is the i-th vertex record, polygon p the p-th face record; a face of k > 3
/// corners becomes the fan (c0, c[j], c[j+1]), j = 1..k-2, with source_polygon p.
///
/// Throws snag::InputError(name_for_errors, ...) with the header or ascii line, or the byte
/// offset in a binary body: malformed header, unsupported property type, missing x/y/z or
/// vertex index list, truncated body, non-number, NaN/Inf coordinate, a face with fewer than 3
/// corners, an index out of range.
mesh::Mesh read_ply(std::string_view bytes, const std::string& name_for_errors);

/// Reads and parses a PLY file.
mesh::Mesh read_ply_file(const std::filesystem::path& path);

}  // namespace snag::io
