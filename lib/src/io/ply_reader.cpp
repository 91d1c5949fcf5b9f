// PLY parsing from one in-memory buffer. The header is parsed into a small schema (elements,
// their properties and types); the body is then walked element by element, reading x/y/z and
// the vertex index list and stepping over everything else. Binary values are loaded with
// memcpy (no alignment assumption) and byte-swapped when the file's byte order is not the
// host's.
#include "snag/io/ply_reader.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_set>
#include <vector>

#include "file_buffer.h"
#include "snag/error.h"
#include "snag/io/read_mesh.h"
#include "structure_cache.h"
#include "text_scan.h"

namespace snag::io {
namespace {

using detail::is_blank;
using detail::is_blank_or_eol;
using detail::quote_token;

enum class Scalar : uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

int scalar_size(Scalar t) {
  switch (t) {
    case Scalar::i8:
    case Scalar::u8:
      return 1;
    case Scalar::i16:
    case Scalar::u16:
      return 2;
    case Scalar::i32:
    case Scalar::u32:
    case Scalar::f32:
      return 4;
    case Scalar::f64:
      return 8;
  }
  return 0;
}

bool is_integer(Scalar t) {
  return t != Scalar::f32 && t != Scalar::f64;
}

/// The values of integer type `t`, lowest and highest.
std::pair<double, double> integer_range(Scalar t) {
  switch (t) {
    case Scalar::i8:
      return {-128.0, 127.0};
    case Scalar::u8:
      return {0.0, 255.0};
    case Scalar::i16:
      return {-32768.0, 32767.0};
    case Scalar::u16:
      return {0.0, 65535.0};
    case Scalar::i32:
      return {-2147483648.0, 2147483647.0};
    case Scalar::u32:
      return {0.0, 4294967295.0};
    default:
      return {0.0, 0.0};
  }
}

/// The header's type names, each type's usual name first.
struct ScalarName {
  std::string_view name;
  Scalar type;
};
constexpr ScalarName kScalarNames[] = {
    {"char", Scalar::i8},     {"int8", Scalar::i8},     {"uchar", Scalar::u8},
    {"uint8", Scalar::u8},    {"short", Scalar::i16},   {"int16", Scalar::i16},
    {"ushort", Scalar::u16},  {"uint16", Scalar::u16},  {"int", Scalar::i32},
    {"int32", Scalar::i32},   {"uint", Scalar::u32},    {"uint32", Scalar::u32},
    {"float", Scalar::f32},   {"float32", Scalar::f32}, {"double", Scalar::f64},
    {"float64", Scalar::f64},
};

bool parse_scalar_name(std::string_view s, Scalar& out) {
  for (const ScalarName& n : kScalarNames) {
    if (n.name == s) {
      out = n.type;
      return true;
    }
  }
  return false;
}

/// The usual name of type `t` in a header (for messages).
std::string_view scalar_type_name(Scalar t) {
  for (const ScalarName& n : kScalarNames)
    if (n.type == t) return n.name;
  return "?";
}

struct Property {
  std::string name;
  Scalar type = Scalar::f32;  // the value type, or the list's item type
  bool is_list = false;
  Scalar count_type = Scalar::u8;
};

struct Element {
  std::string name;
  int64_t count = 0;
  std::vector<Property> properties;
  int64_t header_line = 0;
  bool has_list() const {
    for (const Property& p : properties)
      if (p.is_list) return true;
    return false;
  }
  /// Bytes of one record in a binary body when it has no list (the list's count otherwise).
  int64_t min_record_bytes() const {
    int64_t n = 0;
    for (const Property& p : properties) n += scalar_size(p.is_list ? p.count_type : p.type);
    return n;
  }
};

enum class Format { ascii, binary_little_endian, binary_big_endian };

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  size_t body_offset = 0;  // first byte after the end_header line
  int64_t body_line = 0;   // 1-based line of the body's first byte (ascii)
};

/// Splits a header line into blank-separated words (at most a handful: no allocation beyond
/// the vector reused by the caller).
void split_words(std::string_view line, std::vector<std::string_view>& words) {
  words.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    size_t j = i;
    while (j < line.size() && !is_blank(line[j])) ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
}

std::string quote(std::string_view s) {
  return "'" + detail::printable(s) + "'";
}

Header parse_header(std::string_view bytes, const std::string& name) {
  Header h;
  std::vector<std::string_view> words;
  size_t pos = 0;
  int64_t line = 0;
  bool have_format = false;
  std::unordered_set<std::string> element_property_names;  // the last element's, so far
  auto fail = [&](const std::string& what) -> void { throw InputError(name, line, what); };
  for (;;) {
    if (pos >= bytes.size()) {
      fail(line == 0 ? "file is empty; expected a PLY header starting with 'ply'"
                     : "file ends inside the PLY header; expected an 'end_header' line");
    }
    ++line;
    size_t nl = bytes.find('\n', pos);
    const bool last_line = nl == std::string_view::npos;
    if (last_line) nl = bytes.size();
    std::string_view text = bytes.substr(pos, nl - pos);
    pos = nl + 1;
    split_words(text, words);
    // A header line the file ends inside (no line end after it) is cut short, whatever its
    // words: "pr" of "property" is not an unknown keyword.
    if (last_line && line > 1 && !(words.size() == 1 && words[0] == "end_header"))
      fail("file ends inside the PLY header; expected an 'end_header' line");
    if (line == 1) {
      if (words.size() != 1 || words[0] != "ply") {
        fail("expected 'ply' on the first line, found " +
             (words.empty() ? std::string("an empty line") : quote(text.substr(0, 40))));
      }
      continue;
    }
    if (words.empty()) continue;
    const std::string_view key = words[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      if (words.size() != 1) fail("expected 'end_header' alone on its line, found " + quote(text));
      if (!have_format)
        fail(
            "header has no 'format' line; expected 'format "
            "ascii|binary_little_endian|binary_big_endian 1.0'");
      h.body_offset = std::min(pos, bytes.size());
      h.body_line = line + 1;
      return h;
    }
    if (key == "format") {
      // A second one would silently win, and the body be read in an encoding the first line
      // did not say.
      if (have_format) fail("a second 'format' line; a PLY header has one");
      if (words.size() != 3) fail("expected 'format <encoding> 1.0', found " + quote(text));
      if (words[1] == "ascii") {
        h.format = Format::ascii;
      } else if (words[1] == "binary_little_endian") {
        h.format = Format::binary_little_endian;
      } else if (words[1] == "binary_big_endian") {
        h.format = Format::binary_big_endian;
      } else {
        fail("unknown PLY format " + quote(words[1]) +
             "; expected ascii, binary_little_endian or binary_big_endian");
      }
      // 1.0 is the only version there is; another would be a format this reader cannot know.
      if (words[2] != "1.0") fail("PLY version " + quote(words[2]) + "; expected 1.0");
      have_format = true;
    } else if (key == "element") {
      if (words.size() != 3) fail("expected 'element <name> <count>', found " + quote(text));
      Element e;
      e.name = std::string(words[1]);
      e.header_line = line;
      auto [ptr, ec] = std::from_chars(words[2].data(), words[2].data() + words[2].size(), e.count);
      if (ec != std::errc() || ptr != words[2].data() + words[2].size() || e.count < 0) {
        fail("element " + quote(words[1]) + " has count " + quote(words[2]) +
             "; expected a non-negative integer");
      }
      h.elements.push_back(std::move(e));
      element_property_names.clear();
    } else if (key == "property") {
      if (h.elements.empty()) fail("property before any element: " + quote(text));
      Property p;
      if (words.size() >= 2 && words[1] == "list") {
        if (words.size() != 5)
          fail("expected 'property list <count type> <item type> <name>', found " + quote(text));
        p.is_list = true;
        if (!parse_scalar_name(words[2], p.count_type)) {
          fail("unsupported property type " + quote(words[2]) +
               "; expected char, uchar, short, ushort, int, uint, float, double or int8 ... "
               "float64");
        }
        if (!parse_scalar_name(words[3], p.type)) {
          fail("unsupported property type " + quote(words[3]) +
               "; expected char, uchar, short, ushort, int, uint, float, double or int8 ... "
               "float64");
        }
        if (!is_integer(p.count_type)) {
          fail("list count type " + quote(words[2]) + " is not an integer type");
        }
        p.name = std::string(words[4]);
      } else {
        if (words.size() != 3) fail("expected 'property <type> <name>', found " + quote(text));
        if (!parse_scalar_name(words[1], p.type)) {
          fail("unsupported property type " + quote(words[1]) +
               "; expected char, uchar, short, ushort, int, uint, float, double or int8 ... "
               "float64");
        }
        p.name = std::string(words[2]);
      }
      // A set, not a scan of the earlier ones: a header of 80,000 properties took 35 s.
      if (!element_property_names.insert(p.name).second)
        fail("property " + quote(p.name) + " of element " + quote(h.elements.back().name) +
             " is declared twice");
      h.elements.back().properties.push_back(std::move(p));
    } else {
      fail("unknown header line " + quote(text.substr(0, 60)) +
           "; expected format, element, property, comment, obj_info or end_header");
    }
  }
}

/// What the body walk needs to know: where x, y, z and the index list are.
struct Plan {
  int vertex_element = -1;
  int face_element = -1;
  int xyz[3] = {-1, -1, -1};  // property indices in the vertex element
  int indices = -1;           // property index of the face element's vertex index list
};

Plan make_plan(const Header& h, const std::string& name) {
  Plan plan;
  for (size_t e = 0; e < h.elements.size(); ++e) {
    const Element& el = h.elements[e];
    if (el.name == "vertex" && plan.vertex_element < 0) {
      plan.vertex_element = static_cast<int>(e);
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const Property& p = el.properties[k];
        const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
        if (axis < 0) continue;
        if (p.is_list) {
          throw InputError(
              name, el.header_line,
              "vertex property " + quote(p.name) + " is a list; expected a scalar coordinate");
        }
        plan.xyz[axis] = static_cast<int>(k);
      }
      for (int axis = 0; axis < 3; ++axis) {
        if (plan.xyz[axis] < 0) {
          throw InputError(name, el.header_line,
                           std::string("element 'vertex' has no property '") + "xyz"[axis] +
                               "'; expected x, y and z");
        }
      }
      if (el.count > std::numeric_limits<int32_t>::max()) {
        throw InputError(
            name, el.header_line,
            "vertex count " + std::to_string(el.count) + " exceeds the supported 2^31-1");
      }
    } else if (el.name == "face" && plan.face_element < 0) {
      plan.face_element = static_cast<int>(e);
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const Property& p = el.properties[k];
        if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
          plan.indices = static_cast<int>(k);
          break;
        }
      }
      if (plan.indices < 0) {
        throw InputError(name, el.header_line,
                         "element 'face' has no list property 'vertex_indices' or 'vertex_index'");
      }
      if (!is_integer(el.properties[plan.indices].type)) {
        throw InputError(name, el.header_line,
                         "face vertex indices are floating point; expected an integer type");
      }
      if (el.count > std::numeric_limits<int32_t>::max()) {
        throw InputError(
            name, el.header_line,
            "face count " + std::to_string(el.count) + " exceeds the supported 2^31-1");
      }
    }
  }
  if (plan.vertex_element < 0) throw InputError(name, 0, "PLY header has no 'vertex' element");
  if (plan.face_element < 0) {
    throw InputError(name, 0,
                     "PLY header has no 'face' element; expected a triangle or polygon mesh");
  }
  return plan;
}

/// Adds polygon `polygon` (corners already validated) as a fan of triangles.
void add_polygon(mesh::Mesh& m, const std::vector<int32_t>& corners, int32_t polygon) {
  for (size_t j = 1; j + 1 < corners.size(); ++j) {
    m.triangles.push_back({{corners[0], corners[j], corners[j + 1]}});
    m.source_polygon.push_back(polygon);
    m.triangle_group.push_back(-1);
  }
}

/// `n` and `noun`, plural but for one: "1 byte", "12 bytes", "2 more bytes".
std::string counted(int64_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string record_name(const Element& el, int64_t i) {
  return el.name + " " + std::to_string(i) + " (of " + std::to_string(el.count) + ")";
}

/// Reuse of an earlier frame's structure (structure_cache.h), shared by both encodings. The
/// prefix is the header (element counts, types, encoding); the tail is everything after the
/// vertex element, which must come before the face element for the tail to hold the faces.
class StructureReuse {
 public:
  StructureReuse(detail::StructureCache* cache, std::string_view header)
      : cache_(cache), header_(header) {}

  /// Called once the vertex element `e` is read, `rest` being the next byte: true when the
  /// rest of the file is the cached tail, `mesh` then having the cached structure.
  bool after_vertices(const Plan& plan, size_t e, const char* rest, const char* end,
                      mesh::Mesh& mesh) {
    if (!cache_ || plan.face_element < static_cast<int>(e)) return false;
    tail_start_ = rest;
    if (!cache_->matches(header_, static_cast<int64_t>(mesh.positions.size()), false, {}, rest,
                         end))
      return false;
    cache_->apply(mesh);
    return true;
  }

  /// Called after a parse in full: remembers this file for the next one.
  void parsed_in_full(const char* end, const mesh::Mesh& mesh) {
    if (!cache_) return;
    if (tail_start_)
      cache_->store(header_, false, {}, tail_start_, end, mesh);
    else
      cache_->clear();
  }

 private:
  detail::StructureCache* cache_;  // null: no reuse
  std::string_view header_;
  const char* tail_start_ = nullptr;
};

// ---------------------------------------------------------------------------------------------
// Binary body.

template <bool Swap>
class BinaryBody {
 public:
  BinaryBody(std::string_view bytes, const Header& h, const Plan& plan, const std::string& name,
             detail::StructureCache* cache)
      : base_(bytes.data()),
        p_(bytes.data() + h.body_offset),
        end_(bytes.data() + bytes.size()),
        h_(h),
        plan_(plan),
        name_(name),
        reuse_(cache, bytes.substr(0, h.body_offset)) {}

  mesh::Mesh parse() {
    for (size_t e = 0; e < h_.elements.size(); ++e) {
      const Element& el = h_.elements[e];
      if (static_cast<int>(e) == plan_.vertex_element) {
        read_vertices(el);
        if (reuse_.after_vertices(plan_, e, p_, end_, mesh_)) return std::move(mesh_);
      } else if (static_cast<int>(e) == plan_.face_element) {
        read_faces(el);
      } else {
        skip_element(el);
      }
    }
    // Bytes after the last element's records: a header whose counts are short (faces left
    // unread would be intersections left unchecked).
    if (p_ != end_)
      throw InputError(name_, 0,
                       counted(end_ - p_, "byte") +
                           " after the last element's records; does the header count "
                           "every vertex and face?",
                       offset(p_));
    reuse_.parsed_in_full(end_, mesh_);
    return std::move(mesh_);
  }

 private:
  int64_t offset(const char* p) const { return p - base_; }

  [[noreturn]] void truncated(const Element& el, int64_t i, const char* at, int64_t needed) const {
    throw InputError(name_, 0,
                     "file is truncated: it ends inside " + record_name(el, i) + "; expected " +
                         counted(needed, "more byte") + ", found " + std::to_string(end_ - at),
                     offset(at));
  }
  /// A count the bytes left cannot hold, found before allocating for it (so that a corrupt
  /// count cannot ask for terabytes). With fixed-size records the record the file ends inside
  /// is known; records with lists vary in size, and only a bound is.
  void check_count_fits(const Element& el, int64_t min_bytes) const {
    if (min_bytes <= 0 || el.count <= (end_ - p_) / min_bytes) return;
    const int64_t fit = (end_ - p_) / min_bytes;
    if (!el.has_list()) truncated(el, fit, p_ + fit * min_bytes, min_bytes);
    throw InputError(name_, 0,
                     "file is truncated: the header declares " + std::to_string(el.count) + " " +
                         el.name + " records, and the " + counted(end_ - p_, "byte") +
                         " after this point hold at most " + std::to_string(fit) + " (each takes " +
                         counted(min_bytes, "byte") + " or more)",
                     offset(p_));
  }
  void need(const Element& el, int64_t i, int64_t bytes) const {
    if (end_ - p_ < bytes) truncated(el, i, p_, bytes);
  }

  static uint16_t load16(const char* p) {
    uint16_t v;
    std::memcpy(&v, p, 2);
    if constexpr (Swap) v = __builtin_bswap16(v);
    return v;
  }
  static uint32_t load32(const char* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    if constexpr (Swap) v = __builtin_bswap32(v);
    return v;
  }
  static uint64_t load64(const char* p) {
    uint64_t v;
    std::memcpy(&v, p, 8);
    if constexpr (Swap) v = __builtin_bswap64(v);
    return v;
  }
  /// A binary value of type `t` as a T: double for coordinates, int64_t for counts and
  /// indices (make_plan admits only integer types there, so the float cases never reach it).
  template <class T>
  static T load_as(const char* p, Scalar t) {
    switch (t) {
      case Scalar::i8:
        return static_cast<T>(static_cast<int8_t>(*p));
      case Scalar::u8:
        return static_cast<T>(static_cast<uint8_t>(*p));
      case Scalar::i16:
        return static_cast<T>(static_cast<int16_t>(load16(p)));
      case Scalar::u16:
        return static_cast<T>(load16(p));
      case Scalar::i32:
        return static_cast<T>(static_cast<int32_t>(load32(p)));
      case Scalar::u32:
        return static_cast<T>(load32(p));
      case Scalar::f32:
        return static_cast<T>(std::bit_cast<float>(load32(p)));
      case Scalar::f64:
        return static_cast<T>(std::bit_cast<double>(load64(p)));
    }
    return T{};
  }
  static double load_double(const char* p, Scalar t) { return load_as<double>(p, t); }
  static int64_t load_int(const char* p, Scalar t) { return load_as<int64_t>(p, t); }

  void read_vertices(const Element& el) {
    const int64_t min_bytes = el.min_record_bytes();
    check_count_fits(el, min_bytes);
    mesh_.positions.resize(static_cast<size_t>(el.count));
    int offsets[3];
    Scalar types[3];
    if (!el.has_list()) {
      // Fixed-size records: the coordinates sit at fixed offsets within a fixed stride.
      for (int axis = 0; axis < 3; ++axis) {
        int off = 0;
        for (int k = 0; k < plan_.xyz[axis]; ++k) off += scalar_size(el.properties[k].type);
        offsets[axis] = off;
        types[axis] = el.properties[plan_.xyz[axis]].type;
      }
      if (types[0] == Scalar::f32 && types[1] == Scalar::f32 && types[2] == Scalar::f32) {
        read_float_vertices(el, offsets, min_bytes);
        return;
      }
      for (int64_t i = 0; i < el.count; ++i, p_ += min_bytes) {
        double xyz[3];
        for (int axis = 0; axis < 3; ++axis) {
          xyz[axis] = load_double(p_ + offsets[axis], types[axis]);
          if (!std::isfinite(xyz[axis])) bad_coordinate(el, i, axis, xyz[axis], p_ + offsets[axis]);
        }
        mesh_.positions[i] = {xyz[0], xyz[1], xyz[2]};
      }
      return;
    }
    for (int64_t i = 0; i < el.count; ++i) {
      double xyz[3] = {0, 0, 0};
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const Property& prop = el.properties[k];
        if (prop.is_list) {
          skip_list(el, i, prop);
          continue;
        }
        const int size = scalar_size(prop.type);
        need(el, i, size);
        for (int axis = 0; axis < 3; ++axis) {
          if (plan_.xyz[axis] == static_cast<int>(k)) {
            xyz[axis] = load_double(p_, prop.type);
            if (!std::isfinite(xyz[axis])) bad_coordinate(el, i, axis, xyz[axis], p_);
          }
        }
        p_ += size;
      }
      mesh_.positions[i] = {xyz[0], xyz[1], xyz[2]};
    }
  }

  /// read_vertices' fixed-size records when x, y and z are all floats (what most writers
  /// write): no type dispatch per value, and one test of the records' exponent bits for
  /// finiteness (a float is NaN or infinite when its exponent bits are all ones), the record at
  /// fault found again only when one is not. A third of a binary frame's time in sequence went
  /// to the dispatching loop.
  void read_float_vertices(const Element& el, const int offsets[3], int64_t stride) {
    constexpr uint32_t kExponent = 0x7f800000u;
    geom::Vec3d* const out = mesh_.positions.data();
    const char* const first = p_;
    uint32_t all_ones_somewhere = 0;
    for (int64_t i = 0; i < el.count; ++i, p_ += stride) {
      const uint32_t x = load32(p_ + offsets[0]), y = load32(p_ + offsets[1]),
                     z = load32(p_ + offsets[2]);
      all_ones_somewhere |= static_cast<uint32_t>((x & kExponent) == kExponent) |
                            static_cast<uint32_t>((y & kExponent) == kExponent) |
                            static_cast<uint32_t>((z & kExponent) == kExponent);
      out[i] = {std::bit_cast<float>(x), std::bit_cast<float>(y), std::bit_cast<float>(z)};
    }
    if (!all_ones_somewhere) return;
    for (int64_t i = 0; i < el.count; ++i)
      for (int axis = 0; axis < 3; ++axis) {
        const char* at = first + i * stride + offsets[axis];
        const double v = std::bit_cast<float>(load32(at));
        if (!std::isfinite(v)) bad_coordinate(el, i, axis, v, at);
      }
  }

  [[noreturn]] void bad_coordinate(const Element& el, int64_t i, int axis, double v,
                                   const char* at) const {
    throw InputError(name_, 0,
                     std::string(1, "xyz"[axis]) + " coordinate of " + record_name(el, i) + " is " +
                         (std::isnan(v) ? "NaN" : "infinite") + "; expected a finite number",
                     offset(at));
  }

  void skip_list(const Element& el, int64_t i, const Property& prop) {
    const int count_size = scalar_size(prop.count_type);
    need(el, i, count_size);
    const int64_t n = load_int(p_, prop.count_type);
    if (n < 0) {
      throw InputError(name_, 0,
                       "list " + quote(prop.name) + " of " + record_name(el, i) + " has count " +
                           std::to_string(n) + "; expected a non-negative count",
                       offset(p_));
    }
    p_ += count_size;
    need(el, i, n * scalar_size(prop.type));
    p_ += n * scalar_size(prop.type);
  }

  void read_faces(const Element& el) {
    check_count_fits(el, el.min_record_bytes());
    const Element& vertices = h_.elements[plan_.vertex_element];
    const int64_t vertex_count = vertices.count;
    mesh_.triangles.reserve(static_cast<size_t>(el.count));
    mesh_.source_polygon.reserve(static_cast<size_t>(el.count));
    mesh_.triangle_group.reserve(static_cast<size_t>(el.count));
    const Property& list = el.properties[plan_.indices];
    const int count_size = scalar_size(list.count_type);
    const int index_size = scalar_size(list.type);
    // The usual record (the list alone, a one-byte count, four-byte indices) is read apart while
    // the records are triangles (read_triangle_records): from the first record, and again after
    // each record this loop takes.
    const bool usual = el.properties.size() == 1 && count_size == 1 && index_size == 4;
    for (int64_t i = usual ? read_triangle_records(el, 0, vertex_count) : 0; i < el.count;
         i = usual ? read_triangle_records(el, i + 1, vertex_count) : i + 1) {
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const Property& prop = el.properties[k];
        if (static_cast<int>(k) != plan_.indices) {
          if (prop.is_list) {
            skip_list(el, i, prop);
          } else {
            need(el, i, scalar_size(prop.type));
            p_ += scalar_size(prop.type);
          }
          continue;
        }
        need(el, i, count_size);
        const int64_t n = load_int(p_, list.count_type);
        if (n < 3) {
          throw InputError(
              name_, 0,
              record_name(el, i) + " has " + counted(n, "corner") + "; expected at least 3",
              offset(p_));
        }
        p_ += count_size;
        need(el, i, n * index_size);
        if (n == 3) {
          // Triangles, nearly every face of a simulation frame: no corner buffer, no fan loop.
          int32_t t[3];
          for (int c = 0; c < 3; ++c, p_ += index_size) {
            const int64_t v = load_int(p_, list.type);
            if (v < 0 || v >= vertex_count) bad_index(el, i, c, v, vertex_count);
            t[c] = static_cast<int32_t>(v);
          }
          mesh_.triangles.push_back({{t[0], t[1], t[2]}});
          mesh_.source_polygon.push_back(static_cast<int32_t>(i));
          mesh_.triangle_group.push_back(-1);
          continue;
        }
        corners_.clear();
        for (int64_t c = 0; c < n; ++c, p_ += index_size) {
          const int64_t v = load_int(p_, list.type);
          if (v < 0 || v >= vertex_count) bad_index(el, i, c, v, vertex_count);
          corners_.push_back(static_cast<int32_t>(v));
        }
        add_polygon(mesh_, corners_, static_cast<int32_t>(i));
      }
    }
    mesh_.polygon_count = el.count;
  }

  /// read_faces' records from `first` on while each is a triangle whose record is the index
  /// list alone, its count one byte and its indices four (what most writers write: `property
  /// list uchar int vertex_indices`): 13 bytes a record, read without a type dispatch and
  /// written in place, where the general loop's dispatch and three push_backs a face were most
  /// of a binary frame's parse. Returns the first record it did not take (a polygon, a corner
  /// out of range, a record past the end of the file, or el.count): the general loop takes that
  /// one and reports what is wrong with it.
  int64_t read_triangle_records(const Element& el, int64_t first, int64_t vertex_count) {
    constexpr int64_t kRecordBytes = 13;
    const int64_t available = std::min<int64_t>(el.count - first, (end_ - p_) / kRecordBytes);
    if (available <= 0 || static_cast<uint8_t>(*p_) != 3) return first;  // sized for nothing
    const size_t base = mesh_.triangles.size();
    mesh_.triangles.resize(base + static_cast<size_t>(available));
    mesh_.source_polygon.resize(base + static_cast<size_t>(available));
    geom::Tri* const triangles = mesh_.triangles.data() + base;
    int32_t* const polygons = mesh_.source_polygon.data() + base;
    // As unsigned, a negative int index is as far out of range as one past the last vertex.
    const auto vertices = static_cast<uint64_t>(vertex_count);
    int64_t k = 0;
    for (; k < available; ++k, p_ += kRecordBytes) {
      const uint32_t a = load32(p_ + 1), b = load32(p_ + 5), c = load32(p_ + 9);
      if ((static_cast<uint8_t>(*p_) != 3) | (a >= vertices) | (b >= vertices) | (c >= vertices))
        break;
      triangles[k] = {{static_cast<int32_t>(a), static_cast<int32_t>(b), static_cast<int32_t>(c)}};
      polygons[k] = static_cast<int32_t>(first + k);
    }
    mesh_.triangles.resize(base + static_cast<size_t>(k));
    mesh_.source_polygon.resize(base + static_cast<size_t>(k));
    mesh_.triangle_group.resize(base + static_cast<size_t>(k), -1);
    return first + k;
  }

  [[noreturn]] [[gnu::noinline]] void bad_index(const Element& el, int64_t i, int64_t c, int64_t v,
                                                int64_t vertex_count) const {
    throw InputError(name_, 0,
                     "corner " + std::to_string(c) + " of " + record_name(el, i) + " is vertex " +
                         std::to_string(v) + "; expected 0.." + std::to_string(vertex_count - 1) +
                         " (" + std::to_string(vertex_count) + " vertices)",
                     offset(p_));
  }

  void skip_element(const Element& el) {
    if (!el.has_list()) {
      const int64_t stride = el.min_record_bytes();
      check_count_fits(el, stride);
      p_ += el.count * stride;
      return;
    }
    for (int64_t i = 0; i < el.count; ++i) {
      for (const Property& prop : el.properties) {
        if (prop.is_list) {
          skip_list(el, i, prop);
        } else {
          need(el, i, scalar_size(prop.type));
          p_ += scalar_size(prop.type);
        }
      }
    }
  }

  const char* base_;
  const char* p_;
  const char* end_;
  const Header& h_;
  const Plan& plan_;
  const std::string& name_;
  mesh::Mesh mesh_;
  std::vector<int32_t> corners_;
  StructureReuse reuse_;
};

// ---------------------------------------------------------------------------------------------
// Ascii body: one record per line (blank lines between records passed over), its values
// blank-separated. A line with fewer or more values than its record's properties is an error
// at that line: read as one stream of tokens, a short line borrowed the next line's values and
// the error, if any, surfaced records later. Lines are counted for error messages.

class AsciiBody {
 public:
  AsciiBody(std::string_view bytes, const Header& h, const Plan& plan, const std::string& name,
            detail::StructureCache* cache)
      : p_(bytes.data() + h.body_offset),
        end_(bytes.data() + bytes.size()),
        line_(h.body_line),
        h_(h),
        plan_(plan),
        name_(name),
        reuse_(cache, bytes.substr(0, h.body_offset)) {}

  mesh::Mesh parse() {
    for (size_t e = 0; e < h_.elements.size(); ++e) {
      const Element& el = h_.elements[e];
      const bool is_vertex = static_cast<int>(e) == plan_.vertex_element;
      const bool is_face = static_cast<int>(e) == plan_.face_element;
      // Each record takes at least one character and a separator per value.
      if (el.count > 0 && !el.properties.empty() &&
          el.count > (end_ - p_ + 1) / (2 * static_cast<int64_t>(el.properties.size()))) {
        throw InputError(name_, line_,
                         "element " + quote(el.name) + " declares " + std::to_string(el.count) +
                             " records, more than the rest of the file can hold");
      }
      if (is_vertex) mesh_.positions.reserve(static_cast<size_t>(el.count));
      // An element without properties has records of no values, which take no line.
      const bool has_values = !el.properties.empty();
      for (int64_t i = 0; i < el.count && has_values; ++i) {
        begin_record(el, i);
        if (is_vertex) {
          read_vertex(el, i);
        } else if (is_face) {
          read_face(el, i);
        } else {
          for (const Property& prop : el.properties) {
            const int64_t n = prop.is_list ? next_count(el, i, prop) : 1;
            for (int64_t k = 0; k < n; ++k) next_token(el, i);
          }
        }
        end_record(el, i);
      }
      if (is_face) mesh_.polygon_count = el.count;
      if (is_vertex && reuse_.after_vertices(plan_, e, p_, end_, mesh_)) return std::move(mesh_);
    }
    // Records after the last element's: a header whose counts are short (faces left unread
    // would be intersections left unchecked). Blank lines are fine.
    skip_blank_lines();
    if (p_ != end_)
      fail(quote_token(p_, end_) +
           " after the last element's records; does the header count "
           "every vertex and face?");
    reuse_.parsed_in_full(end_, mesh_);
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_, line_, what); }

  // The checks below are inlined into the loops over records and values; their messages are
  // built out of line (a third of the ascii parse went to calls while they were together).

  /// Moves to the line of record i: past the line end after the record before and any blank
  /// lines, counting them; fails at the end of the file.
  void begin_record(const Element& el, int64_t i) {
    skip_blank_lines();
    if (p_ == end_) [[unlikely]]
      fail_before_record(el, i);
  }

  /// Past blanks and line ends, counting the lines.
  void skip_blank_lines() {
    while (p_ < end_ && is_blank_or_eol(*p_)) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
  }

  /// Past the blanks after record i's last value; fails unless its line ends there.
  void end_record(const Element& el, int64_t i) {
    while (p_ < end_ && is_blank(*p_)) ++p_;
    if (p_ < end_ && *p_ != '\n') [[unlikely]]
      fail_after_record(el, i);
  }

  /// Moves to the start of the record's next value on its line; fails at the line's end.
  const char* skip_to_token(const Element& el, int64_t i) {
    while (p_ < end_ && is_blank(*p_)) ++p_;
    if (p_ == end_ || *p_ == '\n') [[unlikely]]
      fail_inside_record(el, i);
    return p_;
  }

  [[noreturn, gnu::cold, gnu::noinline]] void fail_before_record(const Element& el,
                                                                 int64_t i) const {
    fail("file ends before " + record_name(el, i) + "; expected more records");
  }
  [[noreturn, gnu::cold, gnu::noinline]] void fail_after_record(const Element& el,
                                                                int64_t i) const {
    fail("the line of " + record_name(el, i) + " goes on after its " +
         std::to_string(el.properties.size()) +
         (el.properties.size() == 1 ? " property's" : " properties'") + " values with " +
         quote_token(p_, end_) + "; expected one record per line");
  }
  [[noreturn, gnu::cold, gnu::noinline]] void fail_inside_record(const Element& el,
                                                                 int64_t i) const {
    fail(std::string(p_ == end_ ? "file" : "line") + " ends inside " + record_name(el, i) +
         "; expected more values (one record per line)");
  }

  /// Moves past the next token; returns its start.
  const char* next_token(const Element& el, int64_t i) {
    const char* start = skip_to_token(el, i);
    while (p_ < end_ && !is_blank_or_eol(*p_)) ++p_;
    return start;
  }

  /// The record's next value as an integer; with `length`, its column's usual length, read as
  /// parse_shaped_index reads OBJ's corners.
  int64_t next_integer(const Element& el, int64_t i, const Property& prop, const char* what,
                       uint8_t* length = nullptr) {
    const char* start = skip_to_token(el, i);
    if (length) {
      uint64_t shaped = 0;
      const char* after = detail::parse_shaped_index(start, end_, *length, shaped);
      if (after && detail::ends_token(after, end_)) {
        p_ = after;
        return static_cast<int64_t>(shaped);
      }
    }
    int64_t v = 0;
    auto [ptr, ec] = detail::parse_integer(start, end_, v);
    if (ec != std::errc() || !detail::ends_token(ptr, end_)) {
      fail(std::string("expected an integer ") + what + " for " + quote(prop.name) + " of " +
           record_name(el, i) + ", found " + quote_token(start, end_));
    }
    p_ = ptr;
    return v;
  }

  int64_t next_count(const Element& el, int64_t i, const Property& prop) {
    const int64_t n = next_integer(el, i, prop, "list count");
    if (n < 0) {
      fail("list " + quote(prop.name) + " of " + record_name(el, i) + " has count " +
           std::to_string(n) + "; expected a count >= 0");
    }
    check_fits(el, i, prop, prop.count_type, n, "count");
    return n;
  }

  /// A list's count or item read from the text must be a value of its declared type, as a
  /// binary file's would be (`property list uchar int` holds at most 255 corners).
  void check_fits(const Element& el, int64_t i, const Property& prop, Scalar type, int64_t value,
                  const char* what) const {
    if (static_cast<double>(value) > integer_range(type).second) [[unlikely]]
      fail_fits(el, i, prop, type, value, what);
  }
  [[noreturn, gnu::cold, gnu::noinline]] void fail_fits(const Element& el, int64_t i,
                                                        const Property& prop, Scalar type,
                                                        int64_t value, const char* what) const {
    fail("list " + quote(prop.name) + " of " + record_name(el, i) + " has " + what + " " +
         std::to_string(value) + ", more than its " + std::string(scalar_type_name(type)) +
         " type holds (at most " +
         std::to_string(static_cast<int64_t>(integer_range(type).second)) + ")");
  }

  void read_vertex(const Element& el, int64_t i) {
    double xyz[3] = {0, 0, 0};
    for (size_t k = 0; k < el.properties.size(); ++k) {
      const Property& prop = el.properties[k];
      if (prop.is_list) {
        const int64_t n = next_count(el, i, prop);
        for (int64_t c = 0; c < n; ++c) next_token(el, i);
        continue;
      }
      int axis = 0;
      while (axis < 3 && plan_.xyz[axis] != static_cast<int>(k)) ++axis;
      if (axis == 3) {  // another property of the vertex: skipped
        next_token(el, i);
        continue;
      }
      const char* start = skip_to_token(el, i);
      // A plain decimal of at most 8 + 8 digits, in range of a float: nothing to check but an
      // integer type's range.
      if (detail::parse_shaped(start, end_, shapes_[axis], xyz[axis], p_)) {
        check_integer_value(el, i, prop, axis, start, xyz[axis]);
        continue;
      }
      // The number is parsed straight from the text and must end its token, so that each
      // character is read once.
      const char* first = detail::past_plus(start, end_);
      auto [ptr, ec] = detail::parse_double(first, end_, xyz[axis]);
      if (ec != std::errc() || ptr == first || !detail::ends_token(ptr, end_)) {
        fail(std::string("expected a number for the ") + "xyz"[axis] + " coordinate of " +
             record_name(el, i) + ", found " + quote_token(start, end_));
      }
      if (!std::isfinite(xyz[axis])) {
        fail(std::string(1, "xyz"[axis]) + " coordinate " + quote_token(start, end_) + " of " +
             record_name(el, i) + " is not finite; expected a finite number");
      }
      // A `float` property holds what a float can: a value that rounds to infinity as a float
      // (FLT_MAX plus half its ulp, 2^103, or more) is one a binary file could not hold. In
      // range, the text's value is kept as written, in double precision.
      if (prop.type == Scalar::f32 && std::fabs(xyz[axis]) >= 0x1.ffffffp+127) {
        fail(std::string(1, "xyz"[axis]) + " coordinate " + quote_token(start, end_) + " of " +
             record_name(el, i) + " does not fit its float property; expected a finite float");
      }
      check_integer_value(el, i, prop, axis, start, xyz[axis]);
      p_ = ptr;
    }
    mesh_.positions.push_back({xyz[0], xyz[1], xyz[2]});
  }

  /// A coordinate of an integer property (`property uchar z`) must be a value of that type, as
  /// a binary file's would be: a whole number in the type's range.
  void check_integer_value(const Element& el, int64_t i, const Property& prop, int axis,
                           const char* start, double value) const {
    if (!is_integer(prop.type)) return;
    const auto [low, high] = integer_range(prop.type);
    if (value != std::floor(value) || value < low || value > high) [[unlikely]]
      fail_integer_value(el, i, prop, axis, start, low, high);
  }
  [[noreturn, gnu::cold, gnu::noinline]] void fail_integer_value(const Element& el, int64_t i,
                                                                 const Property& prop, int axis,
                                                                 const char* start, double low,
                                                                 double high) const {
    fail(std::string(1, "xyz"[axis]) + " coordinate " + quote_token(start, end_) + " of " +
         record_name(el, i) + " is not a value of its " + std::string(scalar_type_name(prop.type)) +
         " property; expected a whole number from " + std::to_string(static_cast<int64_t>(low)) +
         " to " + std::to_string(static_cast<int64_t>(high)));
  }

  void read_face(const Element& el, int64_t i) {
    const int64_t vertex_count = h_.elements[plan_.vertex_element].count;
    for (size_t k = 0; k < el.properties.size(); ++k) {
      const Property& prop = el.properties[k];
      if (static_cast<int>(k) != plan_.indices) {
        const int64_t n = prop.is_list ? next_count(el, i, prop) : 1;
        for (int64_t c = 0; c < n; ++c) next_token(el, i);
        continue;
      }
      const int64_t n = next_integer(el, i, prop, "corner count", &count_length_);
      if (n < 3) {
        fail(record_name(el, i) + " has " + counted(n, "corner") + "; expected at least 3");
      }
      check_fits(el, i, prop, prop.count_type, n, "count");
      corners_.clear();
      for (int64_t c = 0; c < n; ++c) {
        const int64_t v = next_integer(el, i, prop, "vertex index",
                                       c < kShapedCorners ? &corner_lengths_[c] : nullptr);
        if (v < 0 || v >= vertex_count) {
          fail("corner " + std::to_string(c) + " of " + record_name(el, i) + " is vertex " +
               std::to_string(v) + "; expected 0.." + std::to_string(vertex_count - 1) + " (" +
               std::to_string(vertex_count) + " vertices)");
        }
        check_fits(el, i, prop, prop.type, v, "vertex index");
        corners_.push_back(static_cast<int32_t>(v));
      }
      add_polygon(mesh_, corners_, static_cast<int32_t>(i));
    }
  }

  const char* p_;
  const char* end_;
  int64_t line_;
  const Header& h_;
  const Plan& plan_;
  const std::string& name_;
  mesh::Mesh mesh_;
  std::vector<int32_t> corners_;
  StructureReuse reuse_;
  detail::DecimalShape shapes_[3];  // the x, y and z columns' last layouts (parse_shaped)
  // The faces' columns' last lengths (parse_shaped_index): the corner count, the first corners.
  static constexpr int64_t kShapedCorners = 8;
  uint8_t count_length_ = 0;
  uint8_t corner_lengths_[kShapedCorners] = {};
};

mesh::Mesh parse_ply(std::string_view bytes, const std::string& name_for_errors,
                     detail::StructureCache* cache) {
  const Header header = parse_header(bytes, name_for_errors);
  const Plan plan = make_plan(header, name_for_errors);
  constexpr bool host_little = std::endian::native == std::endian::little;
  switch (header.format) {
    case Format::ascii:
      return AsciiBody(bytes, header, plan, name_for_errors, cache).parse();
    case Format::binary_little_endian:
      if constexpr (host_little)
        return BinaryBody<false>(bytes, header, plan, name_for_errors, cache).parse();
      else
        return BinaryBody<true>(bytes, header, plan, name_for_errors, cache).parse();
    case Format::binary_big_endian:
      if constexpr (host_little)
        return BinaryBody<true>(bytes, header, plan, name_for_errors, cache).parse();
      else
        return BinaryBody<false>(bytes, header, plan, name_for_errors, cache).parse();
  }
  throw InternalError("unreachable PLY format");
}

}  // namespace

mesh::Mesh read_ply(std::string_view bytes, const std::string& name_for_errors) {
  return parse_ply(bytes, name_for_errors, nullptr);
}

namespace detail {
mesh::Mesh read_ply_reusing(std::string_view bytes, const std::string& name_for_errors,
                            StructureCache& cache) {
  return parse_ply(bytes, name_for_errors, &cache);
}
}  // namespace detail

mesh::Mesh read_ply_file(const std::filesystem::path& path) {
  return read_ply(detail::read_into_thread_buffer(path), path.string());
}

}  // namespace snag::io
