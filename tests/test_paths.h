// Where tests find their inputs: SNAG_SOURCE_DIR (the repository, for samples/) and
// SNAG_DATA_DIR (../shared/data), falling back to the paths known at build time.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace snag::test {

inline std::filesystem::path source_dir() {
  if (const char* env = std::getenv("SNAG_SOURCE_DIR"); env && *env) return env;
#ifdef SNAG_SOURCE_DIR_DEFAULT
  return SNAG_SOURCE_DIR_DEFAULT;
#else
  return ".";
#endif
}

/// Empty when the shared data folder is absent (tests that need it skip with a message).
inline std::filesystem::path data_dir() {
  std::filesystem::path dir;
  if (const char* env = std::getenv("SNAG_DATA_DIR"); env && *env) dir = env;
#ifdef SNAG_DATA_DIR_DEFAULT
  else
    dir = SNAG_DATA_DIR_DEFAULT;
#endif
  if (dir.empty() || !std::filesystem::is_directory(dir)) return {};
  return dir;
}

}  // namespace snag::test
