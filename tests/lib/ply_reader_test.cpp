// PLY reader: three encodings, every scalar type, skipped properties and elements, every
// rejected input, and the real files of ../shared/data.
#include "snag/io/ply_reader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "test_paths.h"

namespace snag::io {
namespace {

using geom::Vec3d;
using Tris = std::vector<std::array<int32_t, 3>>;

Tris tris(const mesh::Mesh& m) {
  Tris out;
  for (const geom::Tri& t : m.triangles) out.push_back({t.v[0], t.v[1], t.v[2]});
  return out;
}

enum class Enc { ascii, le, be };

const char* format_name(Enc e) {
  return e == Enc::ascii ? "ascii" : e == Enc::le ? "binary_little_endian" : "binary_big_endian";
}

/// Writes a PLY body in any encoding: values are appended with the type they are declared with.
class Body {
 public:
  explicit Body(Enc enc) : enc_(enc) {}

  template <class T>
  Body& put(T v) {
    if (enc_ == Enc::ascii) {
      if constexpr (std::is_floating_point_v<T>) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g ", static_cast<double>(v));
        text_ += buf;
      } else {
        text_ += std::to_string(static_cast<int64_t>(v)) + " ";
      }
      return *this;
    }
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if ((enc_ == Enc::be) == (std::endian::native == std::endian::little))
      std::reverse(b, b + sizeof(T));
    text_.append(b, sizeof(T));
    return *this;
  }
  /// Ends a record (a new line in ascii).
  Body& end() {
    if (enc_ == Enc::ascii) text_ += "\n";
    return *this;
  }
  const std::string& str() const { return text_; }

 private:
  Enc enc_;
  std::string text_;
};

std::string header(Enc enc, const std::string& elements) {
  return std::string("ply\nformat ") + format_name(enc) + " 1.0\ncomment made by a test\n" +
         elements + "end_header\n";
}

/// A unit square as one quad and one triangle, written with float xyz and uchar/int lists.
std::string square(Enc enc) {
  Body b(enc);
  const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (auto& p : xy) b.put(p[0]).put(p[1]).put(0.5f).end();
  b.put<uint8_t>(4).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).put<int32_t>(3).end();
  b.put<uint8_t>(3).put<int32_t>(3).put<int32_t>(2).put<int32_t>(1).end();
  return header(enc,
                "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 2\nproperty list uchar int vertex_indices\n") +
         b.str();
}

InputError reject(const std::string& bytes) {
  try {
    read_ply(bytes, "bad.ply");
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted a bad PLY";
  return InputError("", 0, "");
}

void expect_contains(const InputError& e, const std::string& s) {
  EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what();
}

class PlyEncodings : public ::testing::TestWithParam<Enc> {};

TEST_P(PlyEncodings, SquareWithFan) {
  const mesh::Mesh m = read_ply(square(GetParam()), "sq.ply");
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[2], (Vec3d{1, 1, 0.5}));
  EXPECT_EQ(tris(m), (Tris{{0, 1, 2}, {0, 2, 3}, {3, 2, 1}}));
  EXPECT_EQ(m.source_polygon, (std::vector<int32_t>{0, 0, 1}));
  EXPECT_EQ(m.triangle_group, (std::vector<int32_t>{-1, -1, -1}));
  EXPECT_EQ(m.polygon_count, 2);
  EXPECT_FALSE(m.ids_from_assimp);
}

// Triangles, a polygon among them, and triangles again: a binary body's run of triangle records
// is read apart from the rest (read_triangle_records), which must hand over at the polygon with
// the records' ids and groups as the general loop gives them; and a uint index list.
TEST_P(PlyEncodings, TrianglesAroundAPolygonKeepTheirRecordIds) {
  const Enc enc = GetParam();
  for (const char* index_type : {"int", "uint"}) {
    SCOPED_TRACE(index_type);
    Body b(enc);
    for (int i = 0; i < 5; ++i) b.put<float>(1.f * i).put<float>(i % 2).put<float>(0.f).end();
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).end();
    b.put<uint8_t>(3).put<int32_t>(1).put<int32_t>(2).put<int32_t>(3).end();
    b.put<uint8_t>(4).put<int32_t>(0).put<int32_t>(2).put<int32_t>(3).put<int32_t>(4).end();
    b.put<uint8_t>(3).put<int32_t>(2).put<int32_t>(3).put<int32_t>(4).end();
    const mesh::Mesh m =
        read_ply(header(enc,
                        "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 4\nproperty list uchar " +
                            std::string(index_type) + " vertex_indices\n") +
                     b.str(),
                 "run.ply");
    EXPECT_EQ(tris(m), (Tris{{0, 1, 2}, {1, 2, 3}, {0, 2, 3}, {0, 3, 4}, {2, 3, 4}}));
    EXPECT_EQ(m.source_polygon, (std::vector<int32_t>{0, 1, 2, 2, 3}));
    EXPECT_EQ(m.triangle_group, (std::vector<int32_t>(5, -1)));
    EXPECT_EQ(m.polygon_count, 4);
  }
}

TEST_P(PlyEncodings, SkipsOtherPropertiesAndElements) {
  const Enc enc = GetParam();
  Body b(enc);
  // element material 2: a scalar and a list, before the vertices.
  b.put<uint8_t>(7).put<uint16_t>(2).put<float>(0.25f).put<float>(0.5f).end();
  b.put<uint8_t>(8).put<uint16_t>(0).end();
  // element vertex 3: nx (double), z, uchar red, y, list of uint16 tags, x.
  const double xyz[3][3] = {{0.5, 1.5, 2.5}, {-3, 4, 5e-7}, {6, 7, 8}};
  for (auto& p : xyz) {
    b.put<double>(0.0).put<double>(p[2]).put<uint8_t>(255).put<float>(static_cast<float>(p[1]));
    b.put<uint8_t>(2)
        .put<uint16_t>(11)
        .put<uint16_t>(12)
        .put<int16_t>(static_cast<int16_t>(p[0] * 2))
        .end();
  }
  // element face 2: uchar flags, texcoord list of floats, vertex_index list (ushort count, uint
  // indices), int material.
  b.put<uint8_t>(1).put<uint8_t>(2).put<float>(0.1f).put<float>(0.2f);
  b.put<uint16_t>(3).put<uint32_t>(2).put<uint32_t>(1).put<uint32_t>(0).put<int32_t>(-5).end();
  b.put<uint8_t>(0).put<uint8_t>(0);
  b.put<uint16_t>(3).put<uint32_t>(0).put<uint32_t>(1).put<uint32_t>(2).put<int32_t>(9).end();
  // element edge 2 after the faces.
  b.put<int32_t>(0).put<int32_t>(1).end().put<int32_t>(1).put<int32_t>(2).end();
  const std::string text =
      header(enc,
             "element material 2\nproperty uchar id\nproperty list uint16 float32 rgb\n"
             "element vertex 3\nproperty double nx\nproperty double z\nproperty uchar red\n"
             "property float32 y\nproperty list uint8 ushort tags\nproperty short x\n"
             "element face 2\nproperty uchar flags\nproperty list uchar float texcoord\n"
             "property list ushort uint vertex_index\nproperty int material\n"
             "element edge 2\nproperty int vertex1\nproperty int vertex2\n") +
      b.str();
  const mesh::Mesh m = read_ply(text, "t.ply");
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0], (Vec3d{1, 1.5, 2.5}));  // x is a short: 0.5 * 2 = 1
  EXPECT_EQ(m.positions[1], (Vec3d{-6, 4, 5e-7}));
  EXPECT_EQ(m.positions[2], (Vec3d{12, 7, 8}));
  EXPECT_EQ(tris(m), (Tris{{2, 1, 0}, {0, 1, 2}}));
  EXPECT_EQ(m.polygon_count, 2);
}

TEST_P(PlyEncodings, RejectsIndexOutOfRange) {
  const Enc enc = GetParam();
  // The first index past the vertices, in each corner in turn: the binary reader's fast path
  // checks a triangle's corners one by one, and a bound off by one on any of them let the
  // index through to the checker (exit status 4 instead of an input error).
  for (int corner = 0; corner < 3; ++corner) {
    Body b(enc);
    for (int i = 0; i < 3; ++i) b.put<float>(1.f * i).put<float>(0.f).put<float>(0.f).end();
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).end();
    b.put<uint8_t>(3);
    for (int k = 0; k < 3; ++k) b.put<int32_t>(k == corner ? 3 : k);
    b.end();
    const std::string h =
        header(enc,
               "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 2\nproperty list uchar int vertex_indices\n");
    SCOPED_TRACE("corner " + std::to_string(corner));
    const InputError e = reject(h + b.str());
    expect_contains(e, "face 1 (of 2)");
    expect_contains(e, "vertex 3");
    expect_contains(e, "expected 0..2");
    if (enc == Enc::ascii) {
      EXPECT_EQ(e.line(), 15);  // the header's 10 lines, 3 vertices, face 0, then face 1
    } else {
      // The header, 3 vertices of 12 bytes, face 0 (13 bytes), face 1's count and the indices
      // before the bad one.
      EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(h.size() + 36 + 13 + 1 + 4 * corner));
    }
  }
}

TEST_P(PlyEncodings, RejectsNegativeIndexAndShortFaces) {
  const Enc enc = GetParam();
  const std::string h =
      header(enc,
             "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
             "element face 1\nproperty list uchar int vertex_indices\n");
  Body v(enc);
  for (int i = 0; i < 3; ++i) v.put<double>(i).put<double>(0).put<double>(0).end();
  Body neg = v, two = v;
  neg.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(-1).put<int32_t>(2).end();
  expect_contains(reject(h + neg.str()), "vertex -1");
  two.put<uint8_t>(2).put<int32_t>(0).put<int32_t>(1).end();
  const InputError e = reject(h + two.str());
  expect_contains(e, "face 0 (of 1) has 2 corners; expected at least 3");
  if (enc != Enc::ascii) EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(h.size() + 72));
}

TEST_P(PlyEncodings, RejectsNanAndInfCoordinates) {
  const Enc enc = GetParam();
  const std::string h =
      header(enc,
             "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 0\nproperty list uchar int vertex_indices\n");
  for (float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    Body b(enc);
    b.put<float>(0)
        .put<float>(0)
        .put<float>(0)
        .end()
        .put<float>(1)
        .put<float>(bad)
        .put<float>(0)
        .end();
    const InputError e = reject(h + b.str());
    expect_contains(e, "vertex 1 (of 2)");
    if (enc != Enc::ascii) {
      EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(h.size() + 16));
      expect_contains(e, std::isnan(bad) ? "NaN" : "infinite");
    } else {
      EXPECT_EQ(e.line(), 12);
      expect_contains(e, "not finite");
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PlyEncodings,
                         ::testing::Values(Enc::ascii, Enc::le, Enc::be),
                         [](const auto& info) { return std::string(format_name(info.param)); });

// Every scalar type name, as a coordinate and as list count and index type, in every encoding.
struct TypeCase {
  const char* name;
  int kind;  // 0 int8, 1 uint8, 2 int16, 3 uint16, 4 int32, 5 uint32, 6 float, 7 double
};
const TypeCase kTypes[] = {{"char", 0},  {"int8", 0},    {"uchar", 1},  {"uint8", 1},
                           {"short", 2}, {"int16", 2},   {"ushort", 3}, {"uint16", 3},
                           {"int", 4},   {"int32", 4},   {"uint", 5},   {"uint32", 5},
                           {"float", 6}, {"float32", 6}, {"double", 7}, {"float64", 7}};

void put_as(Body& b, int kind, double v) {
  switch (kind) {
    case 0:
      b.put<int8_t>(static_cast<int8_t>(v));
      break;
    case 1:
      b.put<uint8_t>(static_cast<uint8_t>(v));
      break;
    case 2:
      b.put<int16_t>(static_cast<int16_t>(v));
      break;
    case 3:
      b.put<uint16_t>(static_cast<uint16_t>(v));
      break;
    case 4:
      b.put<int32_t>(static_cast<int32_t>(v));
      break;
    case 5:
      b.put<uint32_t>(static_cast<uint32_t>(v));
      break;
    case 6:
      b.put<float>(static_cast<float>(v));
      break;
    default:
      b.put<double>(v);
      break;
  }
}

// Float coordinates among other properties (the records' fixed-size path with offsets): random
// values come back as written, and the first non-finite one is the one named, in every
// encoding.
TEST_P(PlyEncodings, FloatCoordinatesAmongOtherPropertiesAndTheFirstBadOne) {
  const Enc enc = GetParam();
  const int count = 300;
  const std::string h = header(enc, "element vertex " + std::to_string(count) +
                                        "\nproperty uchar red\nproperty float y\nproperty short s\n"
                                        "property float x\nproperty float z\n"
                                        "element face 0\nproperty list uchar int vertex_indices\n");
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(-1e6f, 1e6f);
  std::vector<Vec3d> written;
  Body good(enc);
  for (int i = 0; i < count; ++i) {
    const float x = value(rng), y = value(rng), z = value(rng);
    good.put<uint8_t>(9).put<float>(y).put<int16_t>(-3).put<float>(x).put<float>(z).end();
    written.push_back({x, y, z});
  }
  EXPECT_EQ(read_ply(h + good.str(), "t.ply").positions, written);
  for (const int bad_vertex : {0, 137, count - 1}) {
    Body b(enc);
    for (int i = 0; i < count; ++i) {
      const float z = i == bad_vertex ? std::numeric_limits<float>::infinity() : 1.0f;
      // A NaN in x of a later vertex too: the first bad value is the one named.
      const float x = i == bad_vertex + 1 ? std::numeric_limits<float>::quiet_NaN() : 2.0f;
      b.put<uint8_t>(9).put<float>(3.0f).put<int16_t>(-3).put<float>(x).put<float>(z).end();
    }
    const InputError e = reject(h + b.str());
    expect_contains(e, "z coordinate");
    expect_contains(e, "of vertex " + std::to_string(bad_vertex) + " (of 300)");
    if (enc != Enc::ascii) {
      EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(h.size()) + bad_vertex * 15 + 11);
      expect_contains(e, "infinite");
    }
  }
}

TEST(PlyReader, EveryScalarTypeInEveryEncoding) {
  for (Enc enc : {Enc::ascii, Enc::le, Enc::be}) {
    for (const TypeCase& coord : kTypes) {
      for (const TypeCase& index : kTypes) {
        if (index.kind >= 6) continue;  // indices are integers
        SCOPED_TRACE(std::string(format_name(enc)) + " coord " + coord.name + " index " +
                     index.name);
        // Values every type holds: small, and negative only for signed types.
        const bool coord_signed = coord.kind % 2 == 0 || coord.kind >= 6;
        const double c = coord_signed ? -7 : 7;
        Body b(enc);
        for (int i = 0; i < 4; ++i) {
          put_as(b, coord.kind, c + i);
          put_as(b, coord.kind, i);
          put_as(b, coord.kind, 100);
          b.end();
        }
        put_as(b, index.kind, 4);
        for (int k : {3, 0, 1, 2}) put_as(b, index.kind, k);
        b.end();
        const std::string text =
            header(enc, std::string("element vertex 4\nproperty ") + coord.name + " x\nproperty " +
                            coord.name + " y\nproperty " + coord.name +
                            " z\nelement face 1\nproperty list " + index.name + " " + index.name +
                            " vertex_indices\n") +
            b.str();
        const mesh::Mesh m = read_ply(text, "t.ply");
        ASSERT_EQ(m.positions.size(), 4u);
        EXPECT_EQ(m.positions[3], (Vec3d{c + 3, 3, 100}));
        EXPECT_EQ(tris(m), (Tris{{3, 0, 1}, {3, 1, 2}}));
      }
    }
  }
}

TEST(PlyReader, AsciiToleratesCrlfAndBlankRuns) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n"
      "property float z\r\nelement face 1\r\nproperty list uchar int "
      "vertex_indices\r\nend_header\r\n"
      "0 0 0\r\n1\t0 0\r\n  0 1 +0\r\n\r\n3 0 1 2\r\n";
  const mesh::Mesh m = read_ply(text, "t.ply");
  EXPECT_EQ(tris(m), (Tris{{0, 1, 2}}));
  EXPECT_EQ(m.positions[1], (Vec3d{1, 0, 0}));
}

TEST(PlyReader, BinaryHeaderWithCrlfStartsBodyAfterTheNewline) {
  std::string h = header(Enc::le,
                         "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\n");
  std::string crlf;
  for (char c : h) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  Body b(Enc::le);
  for (int i = 0; i < 3; ++i) b.put<float>(1.f * i).put<float>(2.f).put<float>(3.f);
  b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
  const mesh::Mesh m = read_ply(crlf + b.str(), "t.ply");
  EXPECT_EQ(m.positions[2], (Vec3d{2, 2, 3}));
  EXPECT_EQ(tris(m), (Tris{{0, 1, 2}}));
}

// Bytes after the last element's records (a header counting too few faces, or data appended):
// an error at the first of them, in both byte orders; the faces would otherwise go unread.
TEST(PlyReader, RejectsBytesAfterTheLastBinaryRecord) {
  for (const Enc enc : {Enc::le, Enc::be}) {
    const std::string full = square(enc);
    const InputError e = reject(full + "garbage");
    expect_contains(e, "7 bytes after the last element's records");
    EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(full.size()));
    // Two faces declared as one: the second face's 13 bytes are left over.
    std::string short_count = full;
    const size_t count = short_count.find("element face 2");
    ASSERT_NE(count, std::string::npos);
    short_count[count + 13] = '1';
    expect_contains(reject(short_count), "13 bytes after the last element's records");
  }
}

TEST(PlyReader, RejectsTruncatedBinary) {
  const std::string full = square(Enc::be);
  const size_t body = full.find("end_header\n") + 11;
  // Inside the vertices: vertex 2 of 4 is the first incomplete one.
  {
    const InputError e = reject(full.substr(0, body + 30));
    expect_contains(e, "truncated");
    expect_contains(e, "vertex 2 (of 4)");
    EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(body + 24));
    EXPECT_EQ(e.line(), 0);
  }
  // Inside face 1's index list.
  {
    const InputError e = reject(full.substr(0, full.size() - 2));
    expect_contains(e, "face 1 (of 2)");
    expect_contains(e, "expected 12 more bytes, found 10");
    EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(body + 48 + 17 + 1));
  }
  // Inside a run of triangle records (read_triangle_records stops short of the cut one).
  {
    Body b(Enc::le);
    for (int i = 0; i < 3; ++i) b.put<float>(1.f * i).put<float>(i % 2).put<float>(0.f);
    for (int f = 0; f < 3; ++f) b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    const std::string h =
        header(Enc::le,
               "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 3\nproperty list uchar int vertex_indices\n");
    const std::string whole = h + b.str();
    const InputError e = reject(whole.substr(0, whole.size() - 5));
    expect_contains(e, "face 2 (of 3)");
    expect_contains(e, "expected 12 more bytes, found 7");
    EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(h.size() + 36 + 2 * 13 + 1));
  }
  // Right after the header.
  expect_contains(reject(full.substr(0, body)), "truncated");
  // A huge declared count fails before allocating anything.
  std::string huge = full;
  huge.replace(huge.find("vertex 4"), 8, "vertex 2000000000");
  expect_contains(reject(huge), "truncated");
  // So does a face count too large for the bytes left. Faces vary in size: the message gives
  // the bound, not a face the file would end inside (it named face 936 of a file that ends
  // after face 71, found by fuzzing).
  {
    std::string many = full;
    many.replace(many.find("face 2"), 6, "face 1000");
    const InputError e = reject(many);
    expect_contains(e,
                    "the header declares 1000 face records, and the 30 bytes after this point "
                    "hold at most 30 (each takes 1 byte or more)");
    EXPECT_EQ(e.byte_offset(), static_cast<int64_t>(many.size() - 30));
  }
}

TEST(PlyReader, RejectsTruncatedAscii) {
  std::string text = square(Enc::ascii);
  text.resize(text.size() - 6);  // "2 1 \n" and part of "3 "
  const InputError e = reject(text);
  expect_contains(e, "file ends inside face 1 (of 2)");
}

// One record per line: a short or long line is an error at that line, not values borrowed
// from the next line.
TEST(PlyReader, AsciiRecordsAreOnePerLine) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const auto expect_rejected_at = [&](const std::string& body, int64_t line,
                                      const std::string& what) {
    SCOPED_TRACE(body);
    const InputError e = reject(head + body);
    EXPECT_EQ(e.line(), line);
    expect_contains(e, what);
  };
  // Lines 10 to 13: the vertices, then the face.
  expect_rejected_at("0 0 0\n1 0\n0 1 0 0\n3 0 1 2\n", 11, "line ends inside vertex 1 (of 3)");
  expect_rejected_at("0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n", 11,
                     "the line of vertex 1 (of 3) goes on after its 3 properties' values with '7'");
  expect_rejected_at("0 0 0 1 0 0\n0 1 0\n3 0 1 2\n", 10, "vertex 0 (of 3)");
  expect_rejected_at("0 0 0\n1 0 0\n0 1 0\n3 0 1\n2\n", 13, "line ends inside face 0 (of 1)");
  {
    const InputError e = reject(head + "0 0 0\n1 0 0\n0 1 0\n");
    expect_contains(e, "file ends before face 0 (of 1)");
  }
  // Records after the last element's (a header counting too few faces): an error at the first.
  expect_rejected_at("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n3 2 1 0\n", 15,
                     "'3' after the last element's records");
  // Blank lines between records, blanks at their ends, blank lines after the last and no final
  // line end are fine.
  const mesh::Mesh m = read_ply(head + "\n0 0 0 \n\n1 0 0\t\n0 1 0\n \n3 0 1 2", "t.ply");
  EXPECT_EQ(tris(m), (Tris{{0, 1, 2}}));
  EXPECT_EQ(tris(read_ply(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n \r\n", "t.ply")),
            (Tris{{0, 1, 2}}));
  // An element without properties takes no line; one of one property names it so.
  const std::string vertices =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(
      tris(read_ply(vertices + "element empty 2\n" + faces + "end_header\n" + body + "3 0 1 2\n",
                    "t.ply")),
      (Tris{{0, 1, 2}}));
  expect_contains(reject(vertices + "element flag 1\nproperty uchar f\n" + faces + "end_header\n" +
                         body + "1 2\n3 0 1 2\n"),
                  "the line of flag 0 (of 1) goes on after its 1 property's values with '2'");
}

TEST(PlyReader, RejectsOtherVersionsAndPropertiesDeclaredTwice) {
  const std::string vertex =
      "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n";
  expect_contains(reject("ply\nformat ascii 2.0\n" + vertex + "end_header\n"),
                  "PLY version '2.0'; expected 1.0");
  expect_contains(reject("ply\nformat binary_little_endian 1\n" + vertex + "end_header\n"),
                  "PLY version '1'");
  expect_contains(reject("ply\nformat ascii 1.0\n" + vertex + "property float x\nend_header\n"),
                  "property 'x' of element 'vertex' is declared twice");
  // A header line of binary bytes is quoted printably, NUL included.
  static const char kHeader[] = "ply\nformat ascii 1.0\n\x01\0\xfe\nend_header\n";
  const InputError e = reject(std::string(kHeader, sizeof kHeader - 1));
  expect_contains(e, "'\\x01\\x00\\xfe'");
}

// An integer property's values in an ascii file are those its type holds, as in a binary one.
TEST(PlyReader, AsciiIntegerCoordinatesAreValuesOfTheirType) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty short x\nproperty uchar y\n"
      "property int z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const mesh::Mesh m =
      read_ply(head + "-32768 0 2147483647\n32767 255 -2147483648\n1 2 3\n3 0 1 2\n", "t.ply");
  EXPECT_EQ(m.positions[0], (Vec3d{-32768, 0, 2147483647}));
  EXPECT_EQ(m.positions[1], (Vec3d{32767, 255, -2147483648.0}));
  for (const char* bad :
       {"0 256 0", "0 -1 0", "0 0.5 0", "32768 0 0", "0 0 2147483648", "0 1e2 0.25"}) {
    const InputError e = reject(head + "0 0 0\n" + bad + "\n1 2 3\n3 0 1 2\n");
    EXPECT_EQ(e.line(), 11) << bad;
    expect_contains(e, "is not a value of its");
  }
  expect_contains(reject(head + "0 0 0\n0 256 0\n1 2 3\n3 0 1 2\n"),
                  "y coordinate '256' of vertex 1 (of 3) is not a value of its uchar property; "
                  "expected a whole number from 0 to 255");
}

// A list's count and its corners in an ascii file are values of their declared types too
// (found by fuzzing: a uchar list held a 300-gon and corners past 255).
TEST(PlyReader, AsciiListCountsAndCornersAreValuesOfTheirTypes) {
  std::string vertices;
  for (int v = 0; v < 300; ++v)
    vertices += std::to_string(v) + " " + std::to_string(v % 7) + " 0\n";
  const auto file = [&](const std::string& list, const std::string& face) {
    return "ply\nformat ascii 1.0\nelement vertex 300\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty " +
           list + " vertex_indices\nend_header\n" + vertices + face + "\n";
  };
  std::string gon = "300";
  for (int v = 0; v < 300; ++v) gon += " " + std::to_string(v);
  expect_contains(reject(file("list uchar int", gon)),
                  "list 'vertex_indices' of face 0 (of 1) has count 300, more than its uchar "
                  "type holds (at most 255)");
  EXPECT_EQ(read_ply(file("list ushort int", gon), "t.ply").triangles.size(), 298u);
  expect_contains(reject(file("list uchar uchar", "3 0 1 299")),
                  "has vertex index 299, more than its uchar type holds (at most 255)");
  expect_contains(reject(file("list uchar char", "3 0 1 128")), "more than its char type");
  EXPECT_EQ(read_ply(file("list uchar uchar", "3 0 1 255"), "t.ply").triangles.size(), 1u);
  // A skipped list's count as well.
  const std::string skipped =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list char int texcoord\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  std::string long_list = "128";
  for (int k = 0; k < 128; ++k) long_list += " 0";
  expect_contains(reject(skipped + long_list + " 3 0 1 2\n"),
                  "'texcoord' of face 0 (of 1) has count 128, more than its char type");
}

TEST(PlyReader, RejectsNegativeListCounts) {
  for (Enc enc : {Enc::ascii, Enc::le, Enc::be}) {
    SCOPED_TRACE(format_name(enc));
    Body b(enc);
    for (int i = 0; i < 3; ++i) b.put<float>(1.f * i).put<float>(0.f).put<float>(0.f).end();
    b.put<int8_t>(-2).put<int32_t>(0).end();  // a skipped list with a negative count
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).end();
    const std::string text =
        header(enc,
               "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 1\nproperty list char int texcoord\n"
               "property list uchar int vertex_indices\n") +
        b.str();
    const InputError e = reject(text);
    expect_contains(e, "'texcoord' of face 0 (of 1) has count -2");
  }
}

TEST(PlyReader, RejectsAsciiNonNumbers) {
  std::string text = square(Enc::ascii);
  text.replace(text.find("end_header\n") + 11, 1, "zero");
  const InputError e = reject(text);
  expect_contains(e, "'zero'");
  expect_contains(e, "x coordinate of vertex 0");
  EXPECT_EQ(e.line(), 11);
  std::string index = square(Enc::ascii);
  index.replace(index.rfind("\n3 ") + 3, 1, "3.5");
  expect_contains(reject(index), "'3.5'");
  // A number and text in one token, a sign and nothing, and two signs, as the OBJ reader
  // rejects them; numbers are parsed straight from the text, so each must end its token.
  for (const char* bad : {"1x", "+", "+-1", "1e", "--1"}) {
    SCOPED_TRACE(bad);
    std::string coordinate = square(Enc::ascii);
    coordinate.replace(coordinate.find("end_header\n") + 11, 1, bad);
    const InputError e = reject(coordinate);
    expect_contains(e, "'" + std::string(bad) + "'");
    expect_contains(e, "x coordinate of vertex 0");
  }
  std::string count = square(Enc::ascii);
  count.replace(count.rfind("\n3 ") + 1, 1, "3x");
  expect_contains(reject(count), "expected an integer corner count");
  // The token may end at the end of the file.
  std::string last = square(Enc::ascii);
  while (last.back() == '\n' || last.back() == ' ') last.pop_back();
  EXPECT_EQ(read_ply(last, "t.ply").triangles.size(),
            read_ply(square(Enc::ascii), "t.ply").triangles.size());
}

TEST(PlyReader, RejectsMalformedHeaders) {
  const std::string elements =
      "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 0\nproperty list uchar int vertex_indices\n";
  struct Case {
    std::string text;
    int64_t line;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"", 0, "file is empty"},
      {"plx\nformat ascii 1.0\nend_header\n", 1, "expected 'ply' on the first line, found 'plx'"},
      {"ply\nformat ebcdic 1.0\n" + elements + "end_header\n", 2, "unknown PLY format 'ebcdic'"},
      // Not the second one silently winning (found by fuzzing).
      {"ply\nformat ascii 1.0\nformat binary_big_endian 1.0\n" + elements + "end_header\n", 3,
       "a second 'format' line"},
      {"ply\n" + elements + "end_header\n", 8, "no 'format' line"},
      {"ply\nformat ascii 1.0\n" + elements, 8, "expected an 'end_header' line"},
      {"ply\nformat ascii 1.0\nelement vertex many\n", 3, "count 'many'"},
      {"ply\nformat ascii 1.0\nelement vertex -3\n", 3, "count '-3'"},
      {"ply\nformat ascii 1.0\nproperty float x\n", 3, "property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n", 4,
       "unsupported property type 'half'"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int128 vertex_indices\n", 4,
       "unsupported property type 'int128'"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n", 4,
       "count type 'float' is not an integer"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar\n", 4,
       "expected 'property list"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n", 4,
       "expected 'property <type> <name>'"},
      {"ply\nformat ascii 1.0\nvertices 3\n", 3, "unknown header line 'vertices 3'"},
      {"ply\nformat ascii 1.0\n" + elements + "end_header 0 0 0\n", 9,
       "expected 'end_header' alone on its line"},
      // Cut short inside a header line: not an unknown line "pr", nor a count "1" of "12".
      {"ply\nformat ascii 1.0\nelement vertex 3\npr", 4, "file ends inside the PLY header"},
      {"ply\nformat ascii 1.0\nelement vertex 1", 3, "file ends inside the PLY header"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const InputError e = reject(c.text);
    EXPECT_EQ(e.line(), c.line) << e.what();
    expect_contains(e, c.message);
  }
}

// end_header as the file's last bytes, with no line end: a header whole, its elements empty.
TEST(PlyReader, EndHeaderMayEndTheFile) {
  const mesh::Mesh m = read_ply(
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header",
      "t.ply");
  EXPECT_TRUE(m.positions.empty());
}

TEST(PlyReader, RejectsMissingVertexOrFaceData) {
  const std::string fmt = "ply\nformat binary_little_endian 1.0\n";
  expect_contains(
      reject(fmt + "element vertex 0\nproperty float x\nproperty float y\nend_header\n"),
      "no property 'z'");
  expect_contains(
      reject(fmt + "element face 0\nproperty list uchar int vertex_indices\nend_header\n"),
      "no 'vertex' element");
  expect_contains(
      reject(
          fmt +
          "element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n"),
      "no 'face' element");
  expect_contains(
      reject(fmt + "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 0\nproperty list uchar int corners\nend_header\n"),
      "no list property 'vertex_indices' or 'vertex_index'");
  expect_contains(
      reject(fmt + "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 0\nproperty list uchar float vertex_indices\nend_header\n"),
      "floating point");
}

TEST(PlyReader, EmptyMeshIsAccepted) {
  const mesh::Mesh m =
      read_ply(header(Enc::le,
                      "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 0\nproperty list uchar int vertex_indices\n"),
               "t.ply");
  EXPECT_TRUE(m.positions.empty());
  EXPECT_TRUE(m.triangles.empty());
}

// The real files of ../shared/data, with the face counts its README lists.
TEST(PlyReader, RealFilesLoadWithTheirFaceCounts) {
  const std::filesystem::path data = snag::test::data_dir();
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent (set SNAG_DATA_DIR to run this test)";
  struct Expect {
    const char* file;
    int64_t faces;
  };
  const Expect files[] = {
      {"scalable-ccd/cloth-ball/cloth_ball92.ply", 92230},
      {"scalable-ccd/cloth-ball/cloth_ball93.ply", 92230},
      {"scalable-ccd/cloth-funnel/227.ply", 18484},
      {"scalable-ccd/cloth-funnel/228.ply", 18484},
      {"scalable-ccd/rod-twist/3036.ply", 79864},
      {"scalable-ccd/rod-twist/3037.ply", 79864},
      {"scalable-ccd/armadillo-rollers/326.ply", 24242},
      {"scalable-ccd/armadillo-rollers/327.ply", 24242},
      {"scalable-ccd/n-body-simulation/balls16_18.ply", 146480},
      {"scalable-ccd/n-body-simulation/balls16_19.ply", 146480},
      {"ipc-toolkit/thick-cloth/t0.ply", 404},
      {"ipc-toolkit/thick-cloth/t1.ply", 404},
      {"ipc-toolkit/two-cubes-far.ply", 480},
      {"ipc-toolkit/two-cubes-close.ply", 480},
      {"ipc-toolkit/two-cubes-intersecting.ply", 480},
      {"ipc-toolkit/bunny.ply", 5002},
      {"ipc-toolkit/cube.ply", 12},
      {"ipc-toolkit/height-field.ply", 4904},
  };
  for (const Expect& f : files) {
    SCOPED_TRACE(f.file);
    const mesh::Mesh m = read_mesh(data / f.file);
    EXPECT_EQ(m.polygon_count, f.faces);
    EXPECT_EQ(static_cast<int64_t>(m.triangles.size()), f.faces);
    // Wrong byte order would give absurd coordinates: these scenes are a few units across.
    double extent = 0;
    for (const Vec3d& p : m.positions)
      extent = std::max({extent, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    EXPECT_LT(extent, 1e4);
    EXPECT_GT(extent, 1e-3);
    // Misread faces would not form a surface: in these meshes no edge has more than 2 faces.
    std::vector<std::pair<int32_t, int32_t>> edges;
    for (const geom::Tri& t : m.triangles) {
      for (int k = 0; k < 3; ++k) edges.push_back(std::minmax(t.v[k], t.v[(k + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    size_t overused = 0;
    for (size_t k = 2; k < edges.size(); ++k) overused += edges[k] == edges[k - 2];
    EXPECT_EQ(overused, 0u);
  }
  // The big-endian cloth: 46,598 vertices as its header says.
  EXPECT_EQ(read_mesh(data / "scalable-ccd/cloth-ball/cloth_ball92.ply").positions.size(), 46598u);
}

}  // namespace
}  // namespace snag::io
