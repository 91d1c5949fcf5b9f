// Small helpers of the report tests: a scratch directory, a file's bytes, a listing, and
// report.json's layout made independently of the writers under test.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace snag::report {

/// The layout report.json promises for the document `text` holds, made from the parsed document
/// with nlohmann alone: dump(2)'s (two-space indentation, "key": value, one member or element
/// per line), except that each element of a frame's "pairs" array is one line, the pair as
/// dump() writes it (no spaces). Each pair is swapped for a numbered placeholder string, the
/// document dumped with dump(2), and the placeholders (quoted) replaced by the pairs' dump().
inline std::string report_json_layout(const std::string& text) {
  nlohmann::ordered_json document = nlohmann::ordered_json::parse(text);
  std::vector<std::string> pairs;
  if (document.contains("frames"))
    for (nlohmann::ordered_json& frame : document.at("frames"))
      if (frame.contains("pairs"))
        for (nlohmann::ordered_json& pair : frame.at("pairs")) {
          const std::string placeholder = "\x01pair " + std::to_string(pairs.size());
          pairs.push_back(pair.dump());
          pair = placeholder;
        }
  std::string laid_out = document.dump(2) + "\n";
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::string placeholder = "\"\\u0001pair " + std::to_string(i) + "\"";
    const size_t at = laid_out.find(placeholder);
    if (at == std::string::npos) return "placeholder " + std::to_string(i) + " not found";
    laid_out.replace(at, placeholder.size(), pairs[i]);
  }
  return laid_out;
}

inline std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh directory under the system temporary directory, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("snag-report-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Names in `dir`, hidden ones included, sorted.
inline std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace snag::report
