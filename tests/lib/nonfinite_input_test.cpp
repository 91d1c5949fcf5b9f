// NaN and Inf coordinates are input errors, never silent: every spelling of a non-finite
// number, and every finite text that overflows a double, is rejected by the OBJ and PLY readers
// (all three encodings, float and double properties, fixed-size and list-bearing vertex
// records) and by the assimp path, with the file and the line (text) or byte offset (binary)
// in the message. What obj_reader_test.cpp and ply_reader_test.cpp already cover (OBJ `nan`,
// `inf`, `-Infinity`, `1e999`; PLY float NaN and +Inf) is not repeated here.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "snag/error.h"
#include "snag/io/obj_reader.h"
#include "snag/io/ply_reader.h"
#include "snag/io/read_mesh.h"

namespace snag::io {
namespace {

/// A scratch folder removed at the end of each test.
class TempDir {
 public:
  TempDir()
      : dir_(std::filesystem::temp_directory_path() /
             ("snag_nonfinite_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir_);
  }
  ~TempDir() { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& bytes) const {
    const auto path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

 private:
  std::filesystem::path dir_;
};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Runs `read` and returns the InputError it must throw; a mesh read without an error is a
/// failure that quotes the input.
template <class Read>
InputError rejection(Read read, const std::string& input_for_messages) {
  try {
    const mesh::Mesh m = read();
    size_t nonfinite = 0;
    for (const auto& p : m.positions)
      nonfinite += !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z);
    ADD_FAILURE() << "accepted silently (" << m.positions.size() << " vertices, " << nonfinite
                  << " of them with a NaN or infinite coordinate):\n"
                  << input_for_messages;
  } catch (const InputError& e) {
    return e;
  }
  return InputError("", 0, "");
}

// ---- OBJ -------------------------------------------------------------------------------------

/// The tokens that must be rejected as a coordinate. The finite-looking ones overflow a double.
const char* const kObjBadTokens[] = {
    "nan",   "NaN",     "NAN",      "-nan",  "+nan",     "nan(0x7ff)", "inf",   "-inf",
    "+inf",  "Inf",     "INF",      "-INF",  "infinity", "-Infinity",  "1e400", "-1e400",
    "1e309", "1.8e308", "-1.8e308", "2e308", "1E+400",   "999e999"};

TEST(NonfiniteObj, EverySpellingInEveryCoordinateIsRejectedWithItsLine) {
  for (const char* token : kObjBadTokens) {
    for (int axis = 0; axis < 3; ++axis) {
      std::string coords[3] = {"0.5", "-1", "2"};
      coords[axis] = token;
      // Line 5 after a comment, a blank line and two good vertices.
      const std::string text = "# made by a test\nv 0 0 0\n\nv 1 0 0\nv " + coords[0] + " " +
                               coords[1] + " " + coords[2] + "\nv 0 1 0\nf 1 2 3\nf 2 3 4\n";
      SCOPED_TRACE(text);
      const InputError e = rejection([&] { return read_obj(text, "cloth.0007.obj"); }, text);
      EXPECT_EQ(e.path(), "cloth.0007.obj");
      EXPECT_EQ(e.line(), 5) << e.what();
      EXPECT_TRUE(contains(e.what(), "cloth.0007.obj:5: ")) << e.what();
      EXPECT_TRUE(contains(e.what(), std::string("'") + token + "'")) << e.what();
    }
  }
}

TEST(NonfiniteObj, CrlfTabsAndTheLastLineWithoutNewline) {
  const std::pair<std::string, int64_t> inputs[] = {
      {"v 0 0 0\r\nv 1 0 0\r\nv\t0\t-inf\t0\r\n", 3},
      {"v 0 0 0\nv 1 0 0\nv 0 1 nan", 3},
      {"v 0 0 0\nv 1 0 0\nv 0 1 1e400", 3},
      {"v -inf 0 0 1\n", 1},  // a w coordinate after it changes nothing
      {"v 1 2 3\nv 4 5 6 1\nv 1e400 0 0 1\n", 3},
  };
  for (const auto& [text, line] : inputs) {
    SCOPED_TRACE(text);
    const InputError e = rejection([&] { return read_obj(text, "t.obj"); }, text);
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_TRUE(contains(e.what(), "t.obj:" + std::to_string(line) + ": ")) << e.what();
  }
}

TEST(NonfiniteObj, FiniteExtremesAreAcceptedExactly) {
  // The other side of the line: the largest double, subnormals and signed zeros are numbers.
  const mesh::Mesh m = read_obj(
      "v 1.7976931348623157e308 -1.7976931348623157e308 4.9406564584124654e-324\n"
      "v 2.2250738585072014e-308 -0 0\n",
      "t.obj");
  ASSERT_EQ(m.positions.size(), 2u);
  EXPECT_EQ(m.positions[0].x, std::numeric_limits<double>::max());
  EXPECT_EQ(m.positions[0].y, -std::numeric_limits<double>::max());
  EXPECT_EQ(m.positions[0].z, std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(m.positions[1].x, std::numeric_limits<double>::min());
  EXPECT_TRUE(std::signbit(m.positions[1].y));
}

TEST(NonfiniteObj, ReadMeshNamesTheFileAndLine) {
  const TempDir dir;
  const auto path = dir.write("frame.0003.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n");
  const InputError e = rejection([&] { return read_mesh(path); }, path.string());
  EXPECT_EQ(e.path(), path.string());
  EXPECT_EQ(e.line(), 3);
  EXPECT_TRUE(contains(e.what(), path.string() + ":3: ")) << e.what();
  EXPECT_TRUE(contains(e.what(), "'-inf'")) << e.what();
}

// ---- PLY -------------------------------------------------------------------------------------

enum class Enc { ascii, le, be };
const char* format_name(Enc e) {
  return e == Enc::ascii ? "ascii" : e == Enc::le ? "binary_little_endian" : "binary_big_endian";
}

/// A binary value in the file's byte order.
template <class T>
std::string bytes_of(T v, Enc enc) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if ((enc == Enc::be) == (std::endian::native == std::endian::little))
    std::reverse(b, b + sizeof(T));
  return std::string(b, sizeof(T));
}

/// One non-finite coordinate value: as a binary float and double, and as ascii tokens.
struct BadValue {
  const char* name;
  double value;  ///< the double written in binary files (and cast to float for float files)
};

double nan_with_payload() {
  return std::bit_cast<double>(uint64_t{0x7ff4000000000123});  // signalling, with a payload
}
double negative_nan() {
  return -std::numeric_limits<double>::quiet_NaN();
}

const BadValue kBinaryBad[] = {
    {"quiet NaN", std::numeric_limits<double>::quiet_NaN()},
    {"negative NaN", negative_nan()},
    {"signalling NaN with payload", nan_with_payload()},
    {"+Inf", std::numeric_limits<double>::infinity()},
    {"-Inf", -std::numeric_limits<double>::infinity()},
};

const char* const kPlyAsciiBadTokens[] = {"nan",   "NaN",    "-nan",     "inf",
                                          "-inf",  "+inf",   "Infinity", "-Infinity",
                                          "1e400", "-1e400", "1e309"};

/// A PLY with 3 vertices (x, y, z of type `type`, optionally followed by a list property so
/// that the reader takes its per-property path) and one face; vertex 2's coordinate `axis` is
/// `bad` (binary) or `token` (ascii). Returns the bytes and, for binary, the offset of the bad
/// value; for ascii, its line.
struct PlyFile {
  std::string bytes;
  int64_t bad_at;  ///< byte offset (binary) or line (ascii)
};

PlyFile ply_with(Enc enc, const std::string& type, bool with_list, int axis, double bad,
                 const std::string& token) {
  std::string header = std::string("ply\nformat ") + format_name(enc) +
                       " 1.0\ncomment made by a test\nelement vertex 3\nproperty " + type +
                       " x\nproperty " + type + " y\nproperty " + type + " z\n";
  if (with_list) header += "property list uchar int tags\n";
  header += "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const int64_t header_lines = std::count(header.begin(), header.end(), '\n');
  const double good[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5}};
  std::string body;
  int64_t bad_at = -1;
  for (int v = 0; v < 3; ++v) {
    for (int k = 0; k < 3; ++k) {
      const bool is_bad = v == 2 && k == axis;
      if (enc == Enc::ascii) {
        body += is_bad ? token : std::to_string(good[v][k]);
        body += ' ';
      } else {
        if (is_bad) bad_at = static_cast<int64_t>(header.size() + body.size());
        const double value = is_bad ? bad : good[v][k];
        const bool single = type == "float" || type == "float32";
        body += single ? bytes_of(static_cast<float>(value), enc) : bytes_of(value, enc);
      }
    }
    if (with_list) {
      if (enc == Enc::ascii)
        body += "2 7 8";
      else
        body += bytes_of<uint8_t>(2, enc) + bytes_of<int32_t>(7, enc) + bytes_of<int32_t>(8, enc);
    }
    if (enc == Enc::ascii) body += "\n";
  }
  if (enc == Enc::ascii) {
    bad_at = header_lines + 3;  // vertex 2 is the third body line
    body += "3 0 1 2\n";
  } else {
    body += bytes_of<uint8_t>(3, enc) + bytes_of<int32_t>(0, enc) + bytes_of<int32_t>(1, enc) +
            bytes_of<int32_t>(2, enc);
  }
  return {header + body, bad_at};
}

TEST(NonfinitePly, BinaryNanAndInfInFloatAndDoubleAtTheirByteOffset) {
  int checked = 0;
  for (Enc enc : {Enc::le, Enc::be})
    for (const std::string type : {"float", "double", "float32", "float64"})
      for (bool with_list : {false, true})
        for (const BadValue& bad : kBinaryBad)
          for (int axis = 0; axis < 3; ++axis) {
            const PlyFile file = ply_with(enc, type, with_list, axis, bad.value, "");
            const std::string what = std::string(format_name(enc)) + " " + type +
                                     (with_list ? " with a list" : "") + ", " + bad.name + " as " +
                                     "xyz"[axis];
            SCOPED_TRACE(what);
            const InputError e =
                rejection([&] { return read_ply(file.bytes, "frame.0001.ply"); }, what);
            EXPECT_EQ(e.path(), "frame.0001.ply");
            EXPECT_EQ(e.byte_offset(), file.bad_at) << e.what();
            EXPECT_TRUE(contains(e.what(), "frame.0001.ply")) << e.what();
            EXPECT_TRUE(contains(e.what(), "(byte " + std::to_string(file.bad_at) + ")"))
                << e.what();
            EXPECT_TRUE(contains(e.what(), "vertex 2 (of 3)")) << e.what();
            EXPECT_TRUE(contains(e.what(), std::isnan(bad.value) ? "NaN" : "infinite")) << e.what();
            ++checked;
          }
  EXPECT_EQ(checked, 2 * 4 * 2 * 5 * 3);
}

TEST(NonfinitePly, AsciiTokensForFloatAndDoubleWithTheirLine) {
  for (const std::string type : {"float", "double"})
    for (bool with_list : {false, true})
      for (const char* token : kPlyAsciiBadTokens)
        for (int axis = 0; axis < 3; ++axis) {
          const PlyFile file = ply_with(Enc::ascii, type, with_list, axis, 0, token);
          SCOPED_TRACE(file.bytes);
          const InputError e =
              rejection([&] { return read_ply(file.bytes, "frame.0001.ply"); }, file.bytes);
          EXPECT_EQ(e.line(), file.bad_at) << e.what();
          EXPECT_TRUE(contains(e.what(), "frame.0001.ply:" + std::to_string(file.bad_at) + ": "))
              << e.what();
          EXPECT_TRUE(contains(e.what(), std::string("'") + token + "'")) << e.what();
          EXPECT_TRUE(contains(e.what(), "vertex 2 (of 3)")) << e.what();
        }
}

TEST(NonfinitePly, AsciiFloatPropertyBeyondFloatRangeIsRejectedAndItsLargestValuesKept) {
  // As a float, 1e39 and FLT_MAX + 2^103 (half an ulp above FLT_MAX, rounding to even) are
  // infinite: a binary file could not hold them, so neither may a text one.
  for (const char* token : {"1e39", "-1e39", "340282356779733661637539395458142568448"}) {
    const PlyFile file = ply_with(Enc::ascii, "float", false, 0, 0, token);
    const InputError e =
        rejection([&] { return read_ply(file.bytes, "frame.0001.ply"); }, file.bytes);
    EXPECT_EQ(e.line(), file.bad_at) << e.what();
    EXPECT_TRUE(contains(e.what(), "does not fit its float property")) << e.what();
  }
  // FLT_MAX + 2^102 rounds to FLT_MAX as a float and is kept as written; a double property
  // takes 1e39.
  for (const auto& [type, token, value] :
       {std::tuple{"float", "340282351709131260724621789471329746944", 0x1.fffffe8p127},
        std::tuple{"double", "1e39", 1e39}}) {
    const PlyFile file = ply_with(Enc::ascii, type, false, 0, 0, token);
    const mesh::Mesh m = read_ply(file.bytes, "frame.0001.ply");
    EXPECT_EQ(m.positions.at(2).x, value) << type << " " << token;
  }
}

TEST(NonfinitePly, ReadMeshNamesTheFile) {
  const TempDir dir;
  for (Enc enc : {Enc::ascii, Enc::le}) {
    const PlyFile file =
        ply_with(enc, "double", false, 1, -std::numeric_limits<double>::infinity(), "-inf");
    const auto path = dir.write(std::string("frame_") + format_name(enc) + ".ply", file.bytes);
    const InputError e = rejection([&] { return read_mesh(path); }, path.string());
    EXPECT_EQ(e.path(), path.string());
    if (enc == Enc::ascii) {
      EXPECT_EQ(e.line(), file.bad_at);
      EXPECT_TRUE(contains(e.what(), path.string() + ":" + std::to_string(file.bad_at) + ": "))
          << e.what();
    } else {
      EXPECT_EQ(e.byte_offset(), file.bad_at);
      EXPECT_TRUE(contains(e.what(), path.string() + " (byte " + std::to_string(file.bad_at)))
          << e.what();
    }
  }
}

// ---- Other formats (assimp) ------------------------------------------------------------------

TEST(NonfiniteAssimp, StlAndOffWithNanOrInfAreRejectedNamingTheFile) {
  const TempDir dir;
  const std::pair<const char*, std::string> files[] = {
      {"nan.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 nan 0\n"
       "endloop\nendfacet\nendsolid t\n"},
      {"inf.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 -inf 0\n"
       "endloop\nendfacet\nendsolid t\n"},
      {"overflow.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1e400 0\n"
       "endloop\nendfacet\nendsolid t\n"},
      {"nan.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n"},
      {"inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\ninf 1 0\n3 0 1 2\n"},
  };
  for (const auto& [name, text] : files) {
    const auto path = dir.write(name, text);
    SCOPED_TRACE(name);
    try {
      const mesh::Mesh m = read_mesh(path);
      bool finite = true;
      for (const auto& p : m.positions)
        finite &= std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
      // A reader may reject such a file outright; it must never hand NaN or Inf on.
      EXPECT_TRUE(finite) << name << " came back with a non-finite coordinate:\n" << text;
      ADD_FAILURE() << name << " was accepted silently (" << m.positions.size() << " vertices, "
                    << m.triangles.size() << " triangles):\n"
                    << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path.string()) << e.what();
      EXPECT_TRUE(contains(e.what(), path.string())) << e.what();
    }
  }
}

}  // namespace
}  // namespace snag::io
