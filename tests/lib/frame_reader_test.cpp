// FrameReader: reusing an earlier frame's faces gives exactly what read_mesh gives, result for
// result and error for error, whatever differs between the frames; reuse happens only where
// the bytes allow it.
#include <gtest/gtest.h>

#include <unistd.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "snag/error.h"
#include "snag/io/read_mesh.h"

namespace snag::io {
namespace {

namespace fs = std::filesystem;

class FrameReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("snag-frame-reader-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes `bytes` as a new file with the extension `ext` and returns its path.
  fs::path write(const std::string& bytes, const std::string& ext) {
    const fs::path path = dir_ / ("frame" + std::to_string(files_++) + ext);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  fs::path dir_;
  int files_ = 0;
};

/// What read_mesh makes of a file: the mesh, or the error's message.
struct Outcome {
  mesh::Mesh mesh;
  std::string error;
};

Outcome outcome_of(auto&& read) {
  Outcome out;
  try {
    out.mesh = read();
  } catch (const InputError& e) {
    out.error = e.what();
  }
  return out;
}

void expect_same(const Outcome& got, const Outcome& want) {
  EXPECT_EQ(got.error, want.error);
  if (!want.error.empty()) return;
  const mesh::Mesh& a = got.mesh;
  const mesh::Mesh& b = want.mesh;
  EXPECT_EQ(a.positions, b.positions);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t t = 0; t < a.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.triangles[t].v[k], b.triangles[t].v[k]) << t;
  EXPECT_EQ(a.source_polygon, b.source_polygon);
  EXPECT_EQ(a.triangle_group, b.triangle_group);
  EXPECT_EQ(a.group_names, b.group_names);
  EXPECT_EQ(a.polygon_count, b.polygon_count);
}

/// Reads `first` then `second` with one FrameReader and checks the second against read_mesh.
/// Returns whether the second frame reused the first's structure.
bool second_frame_agrees(const fs::path& first, const fs::path& second) {
  FrameReader reader;
  const Outcome first_got = outcome_of([&] { return reader.read(first); });
  expect_same(first_got, outcome_of([&] { return read_mesh(first); }));
  const int64_t before = reader.frames_reused();
  const Outcome got = outcome_of([&] { return reader.read(second); });
  expect_same(got, outcome_of([&] { return read_mesh(second); }));
  return reader.frames_reused() > before;
}

const std::string obj_faces = "f 1 2 3\nf 1 3 4 2\nf -1 -2 -3\n";

TEST_F(FrameReaderTest, ObjFramesThatDifferInPositionsOnlyReuseTheFaces) {
  const fs::path a = write("# frame 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n" + obj_faces, ".obj");
  const fs::path b =
      write("# frame 2, t = 0.04\nv 0 0 1\nv 1.5 0 0\nv 0 1 0\nv 1 1 2e-3\n" + obj_faces, ".obj");
  EXPECT_TRUE(second_frame_agrees(a, b));
}

TEST_F(FrameReaderTest, ObjChangesAreParsedInFull) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
  const fs::path base = write("o cloth\n" + vertices + obj_faces, ".obj");
  struct Variant {
    const char* what;
    std::string text;
    bool reusable;
  };
  const std::vector<Variant> variants = {
      {"positions only", "o cloth\nv 0 0 9\nv 1 0 0\nv 0 1 0\nv 1 1 0\n" + obj_faces, true},
      // The group named before the vertices is parser state at the tail's start.
      {"group renamed before the vertices", "o dress\n" + vertices + obj_faces, false},
      {"no group", vertices + obj_faces, false},
      {"a face changed", "o cloth\n" + vertices + "f 1 2 4\nf 1 3 4 2\nf -1 -2 -3\n", false},
      // Same tail bytes, one more vertex: the relative indices mean other vertices.
      {"one more vertex", "o cloth\n" + vertices + "v 2 2 2\n" + obj_faces, false},
      {"one vertex fewer", "o cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\n" + obj_faces, false},
      {"a vertex after the faces", "o cloth\n" + vertices + obj_faces + "v 3 3 3\n", false},
      {"a face before a vertex",
       "o cloth\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 0\n"
       "f 1 3 4 2\nf -1 -2 -3\n",
       false},
      {"a bad coordinate", "o cloth\nv 0 0 nan\nv 1 0 0\nv 0 1 0\nv 1 1 0\n" + obj_faces, false},
      {"a bad index", "o cloth\n" + vertices + "f 1 2 3\nf 1 3 4 2\nf -1 -2 -9\n", false},
      {"no newline at the end", "o cloth\n" + vertices + obj_faces.substr(0, obj_faces.size() - 1),
       false},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.what);
    EXPECT_EQ(second_frame_agrees(base, write(v.text, ".obj")), v.reusable);
  }
}

TEST_F(FrameReaderTest, ObjLayoutsWithoutATailAreNeverReused) {
  // Faces interleaved with vertices: nothing is remembered, every frame is parsed in full.
  const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 0\nf 2 3 4\n";
  FrameReader reader;
  for (int i = 0; i < 3; ++i) {
    const fs::path path = write(text, ".obj");
    expect_same(outcome_of([&] { return reader.read(path); }),
                outcome_of([&] { return read_mesh(path); }));
  }
  EXPECT_EQ(reader.frames_reused(), 0);
}

// PLY files: an ascii one and its binary encodings, built from one list of vertices and faces.
struct PlyMesh {
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::vector<int32_t>> faces;
};

std::string ply_header(const PlyMesh& m, const std::string& format, bool faces_first = false) {
  const std::string vertex = "element vertex " + std::to_string(m.vertices.size()) +
                             "\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face " + std::to_string(m.faces.size()) +
                           "\nproperty list uchar int vertex_indices\n";
  return "ply\nformat " + format + " 1.0\ncomment made by a test\n" +
         (faces_first ? face + vertex : vertex + face) + "end_header\n";
}

std::string ascii_ply(const PlyMesh& m) {
  std::string s = ply_header(m, "ascii");
  for (const auto& v : m.vertices)
    s += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
  for (const auto& f : m.faces) {
    s += std::to_string(f.size());
    for (int32_t i : f) s += " " + std::to_string(i);
    s += "\n";
  }
  return s;
}

template <class T>
void put(std::string& s, T value, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big))
    std::reverse(bytes, bytes + sizeof(T));
  s.append(bytes, sizeof(T));
}

std::string binary_ply(const PlyMesh& m, bool big_endian, bool faces_first = false) {
  std::string s =
      ply_header(m, big_endian ? "binary_big_endian" : "binary_little_endian", faces_first);
  std::string vertices, faces;
  for (const auto& v : m.vertices)
    for (float x : v) put(vertices, x, big_endian);
  for (const auto& f : m.faces) {
    put(faces, static_cast<uint8_t>(f.size()), big_endian);
    for (int32_t i : f) put(faces, i, big_endian);
  }
  return s + (faces_first ? faces + vertices : vertices + faces);
}

TEST_F(FrameReaderTest, PlyChangesAreParsedInFullInEveryEncoding) {
  const PlyMesh base{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2}, {0, 2, 3, 1}}};
  PlyMesh moved = base;
  moved.vertices[2] = {0.25f, 1, 0.5f};
  PlyMesh refaced = moved;
  refaced.faces[0] = {0, 1, 3};
  PlyMesh bigger = moved;
  bigger.vertices.push_back({2, 2, 2});
  PlyMesh bad_index = moved;
  bad_index.faces[1][2] = 7;
  PlyMesh bad_coordinate = moved;
  bad_coordinate.vertices[0][1] = std::numeric_limits<float>::infinity();

  const auto encodings = {
      std::function<std::string(const PlyMesh&)>(ascii_ply),
      std::function<std::string(const PlyMesh&)>(
          [](const PlyMesh& m) { return binary_ply(m, false); }),
      std::function<std::string(const PlyMesh&)>(
          [](const PlyMesh& m) { return binary_ply(m, true); }),
  };
  int encoding = 0;
  for (const auto& encode : encodings) {
    SCOPED_TRACE("encoding " + std::to_string(encoding++));
    const fs::path first = write(encode(base), ".ply");
    EXPECT_TRUE(second_frame_agrees(first, write(encode(moved), ".ply")));
    EXPECT_FALSE(second_frame_agrees(first, write(encode(refaced), ".ply")));
    EXPECT_FALSE(second_frame_agrees(first, write(encode(bigger), ".ply")));
    EXPECT_FALSE(second_frame_agrees(first, write(encode(bad_index), ".ply")));
    if (encoding > 1)  // ascii cannot write an infinity that std::to_string would read back
      EXPECT_FALSE(second_frame_agrees(first, write(encode(bad_coordinate), ".ply")));
  }
  // Faces before vertices: the faces are not after the vertex element, nothing is reused.
  const fs::path faces_first = write(binary_ply(base, false, true), ".ply");
  EXPECT_FALSE(second_frame_agrees(faces_first, write(binary_ply(moved, false, true), ".ply")));
  // Another format in between: an OBJ's tail never matches a PLY's.
  EXPECT_FALSE(second_frame_agrees(write(ascii_ply(base), ".ply"),
                                   write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n", ".obj")));
}

TEST_F(FrameReaderTest, RandomEditsAgreeWithReadMesh) {
  // A frame, then copies with random bytes changed, inserted or removed: whatever the edit, the
  // reader that saw the original agrees with read_mesh.
  std::string text = "# cloth\no cloth\n";
  for (int i = 0; i < 6; ++i)
    text += "v " + std::to_string(i % 3) + " " + std::to_string(i / 3) + " 0.5\n";
  text += "g front\nf 1 2 5 4\nf 2 3 6 5\ng back\nf -1 -2 -3\n";
  const fs::path base = write(text, ".obj");
  std::mt19937 rng(7);
  const std::string alphabet = "0123456789 -./\nvfog#";
  int reused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string edited = text;
    const size_t at = rng() % edited.size();
    switch (rng() % 3) {
      case 0:
        edited[at] = alphabet[rng() % alphabet.size()];
        break;
      case 1:
        edited.insert(at, 1, alphabet[rng() % alphabet.size()]);
        break;
      default:
        edited.erase(at, 1);
    }
    SCOPED_TRACE(edited);
    reused += second_frame_agrees(base, write(edited, ".obj"));
  }
  // Edits inside the vertex lines keep the tail: some frames are reused, most are not.
  EXPECT_GT(reused, 0);
  EXPECT_LT(reused, 400);
}

}  // namespace
}  // namespace snag::io
