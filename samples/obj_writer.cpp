#include "obj_writer.h"

#include <charconv>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace snag::samples {
namespace {

// Appends `value` in fixed notation. std::to_chars is exact and locale-independent; a result that
// rounds to zero loses its sign so that a particle at -1e-9 does not print as "-0.000000".
void append_fixed(std::string& out, double value, int decimals) {
  char buffer[64];
  const auto [end, error] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
  if (error != std::errc{}) {
    throw std::runtime_error("cannot format coordinate " + std::to_string(value) +
                             " (is the simulation unstable?)");
  }
  const char* begin = buffer;
  if (*begin == '-') {
    bool all_zero = true;
    for (const char* c = begin + 1; c != end; ++c) {
      all_zero = all_zero && (*c == '0' || *c == '.');
    }
    if (all_zero) {
      ++begin;
    }
  }
  out.append(begin, std::size_t(end - begin));
}

void append_int(std::string& out, int value) {
  char buffer[16];
  const char* end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  out.append(buffer, std::size_t(end - buffer));
}

}  // namespace

void write_obj(const std::filesystem::path& path, const Eigen::Matrix3Xd& positions,
               const std::vector<std::array<int, 3>>& triangles, int decimals,
               const std::vector<std::string>& header) {
  if (decimals < 0 || decimals > 17) {
    throw std::invalid_argument("decimals must be in 0..17, got " + std::to_string(decimals));
  }
  // One buffer per file: about 40 bytes per vertex and 20 per face at 6 decimals.
  std::string text;
  text.reserve(std::size_t(positions.cols()) * (3 * (decimals + 6) + 3) + triangles.size() * 24);
  for (const std::string& line : header) {
    text += "# ";
    text += line;
    text += '\n';
  }
  for (Eigen::Index v = 0; v < positions.cols(); ++v) {
    text += 'v';
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      append_fixed(text, positions(k, v), decimals);
    }
    text += '\n';
  }
  for (const auto& triangle : triangles) {
    text += 'f';
    for (int corner : triangle) {
      text += ' ';
      append_int(text, corner + 1);
    }
    text += '\n';
  }

  std::filesystem::path temporary = path;
  temporary += ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) {
      throw std::runtime_error("cannot open " + temporary.string() + " for writing");
    }
    file.write(text.data(), std::streamsize(text.size()));
    if (!file) {
      throw std::runtime_error("cannot write " + temporary.string());
    }
  }
  std::filesystem::rename(temporary, path);
}

}  // namespace snag::samples
