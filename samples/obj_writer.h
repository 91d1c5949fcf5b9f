// Writing one OBJ frame: `v x y z` lines with a fixed number of decimals, then `f a b c` lines.
#pragma once

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace snag::samples {

// Writes `positions` (3 x vertex count) and `triangles` (0-based, written 1-based) to `path`,
// preceded by the `header` lines as `# ` comments. Coordinates are printed in fixed notation with
// `decimals` digits after the point (0..17), rounded to nearest, never as "-0.000"; the bytes
// depend only on the values, not on the locale. The file is written under a temporary name and
// renamed, so a reader never sees half a frame. Throws std::runtime_error on I/O failure.
void write_obj(const std::filesystem::path& path, const Eigen::Matrix3Xd& positions,
               const std::vector<std::array<int, 3>>& triangles, int decimals,
               const std::vector<std::string>& header);

}  // namespace snag::samples
