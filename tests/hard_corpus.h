// The hard-case corpus (samples/hard/, written by samples/hard_cases.cpp) as the tests read
// it: cases.csv (case,file,weld,degenerate_faces,description) and expected.csv
// (case,face_a,face_b,kind), checked strictly, and each case's mesh with the triangles the
// checker sees (welded where the case says so, as `snag check --weld` does).
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "snag/detect/result.h"
#include "snag/io/read_mesh.h"
#include "snag/mesh/weld.h"
#include "test_paths.h"

namespace snag::test {

struct CorpusCase {
  std::string name;
  std::string file;
  std::string weld;  // empty: no weld
  std::vector<int32_t> degenerate;
  std::string description;
  std::vector<detect::FacePair> expected;  // sorted by (a, b)
};

inline std::filesystem::path corpus_dir() {
  return source_dir() / "samples" / "hard";
}

inline std::vector<std::string> split_csv_line(const std::string& line, size_t fields) {
  // The corpus has no quoted fields: the generator rejects commas in descriptions.
  std::vector<std::string> out;
  size_t start = 0;
  while (out.size() + 1 < fields) {
    const size_t comma = line.find(',', start);
    if (comma == std::string::npos) break;
    out.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
  out.push_back(line.substr(start));
  return out;
}

inline std::vector<std::string> csv_rows(const std::filesystem::path& path,
                                         const std::string& header) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::vector<std::string> rows;
  std::string line;
  if (!std::getline(in, line) || line != header)
    throw std::runtime_error(path.string() + ": expected the header '" + header + "', found '" +
                             line + "'");
  while (std::getline(in, line))
    if (!line.empty()) rows.push_back(line);
  return rows;
}

/// The corpus as written down; throws with the file and row on anything malformed.
inline std::vector<CorpusCase> load_corpus() {
  std::vector<CorpusCase> cases;
  std::map<std::string, size_t> index;
  for (const std::string& row :
       csv_rows(corpus_dir() / "cases.csv", "case,file,weld,degenerate_faces,description")) {
    const auto f = split_csv_line(row, 5);
    if (f.size() != 5) throw std::runtime_error("cases.csv: row '" + row + "' has not 5 fields");
    CorpusCase c{f[0], f[1], f[2], {}, f[4], {}};
    std::istringstream ids(f[3]);
    for (int32_t id; ids >> id;) c.degenerate.push_back(id);
    if (!index.emplace(c.name, cases.size()).second)
      throw std::runtime_error("cases.csv: case " + c.name + " listed twice");
    cases.push_back(std::move(c));
  }
  for (const std::string& row :
       csv_rows(corpus_dir() / "expected.csv", "case,face_a,face_b,kind")) {
    const auto f = split_csv_line(row, 4);
    const auto it = f.size() == 4 ? index.find(f[0]) : index.end();
    if (it == index.end())
      throw std::runtime_error("expected.csv: row '" + row + "' names no case of cases.csv");
    detect::FacePair p{std::stoi(f[1]), std::stoi(f[2]), detect::PairKind::touching};
    if (f[3] == "crossing")
      p.kind = detect::PairKind::crossing;
    else if (f[3] != "touching")
      throw std::runtime_error("expected.csv: row '" + row + "': kind is not crossing/touching");
    if (!(0 <= p.a && p.a < p.b))
      throw std::runtime_error("expected.csv: row '" + row + "': expected 0 <= face_a < face_b");
    cases[it->second].expected.push_back(p);
  }
  for (CorpusCase& c : cases)
    std::sort(c.expected.begin(), c.expected.end(), [](const auto& x, const auto& y) {
      return std::pair(x.a, x.b) < std::pair(y.a, y.b);
    });
  return cases;
}

/// Empty (and the corpus test fails) when the corpus cannot be read.
inline std::vector<CorpusCase> corpus_or_empty() {
  try {
    return load_corpus();
  } catch (const std::exception&) {
    return {};
  }
}

/// The case's mesh and the triangles the checker sees: corners replaced by their weld
/// representatives when the case has a weld, as `snag check --weld` does.
struct LoadedCase {
  mesh::Mesh mesh;
  std::vector<geom::Tri> triangles;
};

inline LoadedCase load(const CorpusCase& c) {
  LoadedCase out{io::read_mesh(corpus_dir() / c.file), {}};
  out.triangles = mesh::welded_triangles(
      out.mesh.triangles, c.weld.empty()
                              ? std::vector<int32_t>{}
                              : mesh::weld_representatives(out.mesh.positions, std::stod(c.weld)));
  return out;
}

}  // namespace snag::test
