// OBJ parsing from one in-memory buffer: one pass, no per-line allocation, numbers through
// detail::parse_shaped and parse_shaped_index (each column's usual layout, read without a
// loop), else detail::parse_double (fast_float behind a fast path) and parse_integer. Only `v`,
// `f`, `o` and `g` are looked at; every other line costs one memchr to find its end.
#include "snag/io/obj_reader.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <unordered_map>
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

class ObjParser {
 public:
  ObjParser(std::string_view text, const std::string& name, detail::StructureCache* cache)
      : p_(text.data()), end_(text.data() + text.size()), name_(name), cache_(cache) {
    // A UTF-8 byte order mark, which some Windows tools write: not part of the first line.
    if (text.starts_with("\xEF\xBB\xBF")) p_ += 3;
  }

  mesh::Mesh parse() {
    if (cache_ && cache_->valid) {
      // Most likely the remembered layout: its sizes, without the counting pass.
      mesh_.positions.reserve(static_cast<size_t>(cache_->vertex_count));
      mesh_.triangles.reserve(cache_->structure.triangles.size());
      mesh_.source_polygon.reserve(cache_->structure.triangles.size());
      mesh_.triangle_group.reserve(cache_->structure.triangles.size());
    } else {
      reserve();
    }
    while (p_ < end_) {
      while (p_ < end_ && is_blank(*p_)) ++p_;
      if (p_ == end_) break;
      const char c = *p_;
      const bool keyword_alone = p_ + 1 == end_ || is_blank_or_eol(p_[1]);
      if (c == '\n') {
        ++p_;
        ++line_;
        continue;
      }
      if (keyword_alone && c == 'v') {
        parse_vertex();
        skip_line();
        if (tail_matches_cache()) return std::move(mesh_);
        continue;
      }
      if (keyword_alone && c == 'f') {
        parse_face();
      } else if (keyword_alone && (c == 'o' || c == 'g')) {
        parse_group();
      } else {
        pass_over_line();
        continue;
      }
      skip_line();
    }
    check_forward_references();
    if (cache_) {
      if (tail_start_)
        cache_->store({}, tail_pending_, tail_pending_name_, tail_start_, end_, mesh_);
      else
        cache_->clear();
    }
    return std::move(mesh_);
  }

 private:
  /// Sizes the arrays from a count of `v ` and `f ` lines (one memchr per line, about a tenth
  /// of the parse), so that they are not copied while growing: with exact sizes the parse
  /// touches each output page once. Polygons with more corners grow the triangle arrays later.
  void reserve() {
    size_t vertices = 0, faces = 0;
    for (const char* q = p_; q < end_;) {
      if (q + 1 < end_ && (q[1] == ' ' || q[1] == '\t')) {
        vertices += q[0] == 'v';
        faces += q[0] == 'f';
      }
      const char* nl = detail::find_eol(q, end_);
      if (nl == end_) break;
      q = nl + 1;
    }
    mesh_.positions.reserve(vertices);
    mesh_.triangles.reserve(faces);
    mesh_.source_polygon.reserve(faces);
    mesh_.triangle_group.reserve(faces);
  }

  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_, line_, what); }

  /// Called at the end of every vertex line. While no face has been listed, the rest of the
  /// file could be the tail of structure_cache.h: remember where it starts and the pending
  /// group name (the only parser state that carries into faces before any face), and when it
  /// is the cached frame's tail, take that frame's structure instead of parsing it again.
  bool tail_matches_cache() {
    if (mesh_.polygon_count != 0) {
      tail_start_ = nullptr;  // a vertex after a face: this layout is not cached
      return false;
    }
    tail_start_ = p_;
    tail_pending_ = group_pending_;
    tail_pending_name_ = pending_name_;
    if (!cache_ || !cache_->matches({}, static_cast<int64_t>(mesh_.positions.size()),
                                    group_pending_, pending_name_, p_, end_))
      return false;
    cache_->apply(mesh_);
    return true;
  }

  /// Passes over a line snag does not read (a comment, or a record such as vt, vn, s, usemtl,
  /// a simulator's own), which must still look like OBJ: a keyword's letter or '#' first, and no
  /// lone CR. Otherwise a binary or compressed file, a file whose lines end with a lone CR (one
  /// long comment), or "v0 0 0" (a vertex lost, every later index off by one) would check clean.
  void pass_over_line() {
    const char c = *p_;
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
    if (!letter && c != '#') {
      const auto byte = static_cast<unsigned char>(c);
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", byte);
      fail("a line starting with " +
           (byte < 0x20 || byte >= 0x7f ? "byte " + std::string(hex) : quote_token(p_, end_)) +
           " is not an OBJ record (a keyword or '#'); is this a binary or compressed file?");
    }
    if ((c == 'v' || c == 'f') && p_ + 1 < end_ &&
        ((p_[1] >= '0' && p_[1] <= '9') || p_[1] == '-' || p_[1] == '+' || p_[1] == '.'))
      fail("expected a blank after '" + std::string(1, c) + "', found " + quote_token(p_, end_));
    const char* eol = detail::find_eol(p_, end_);
    refuse_lone_cr(eol);
    p_ = eol;
    if (p_ < end_) {
      ++p_;
      ++line_;
    }
  }

  void skip_line() {
    // A parsed `v` or `f` line usually stops right at its end: no memchr call needed.
    while (p_ < end_ && is_blank(*p_)) ++p_;
    if (p_ < end_ && *p_ == '\n') {
      ++p_;
      ++line_;
      return;
    }
    p_ = detail::find_eol(p_, end_);
    if (p_ < end_) {
      ++p_;
      ++line_;
    }
  }

  void skip_blanks() {
    while (p_ < end_ && is_blank(*p_)) ++p_;
  }
  bool at_eol() const { return p_ == end_ || *p_ == '\n'; }

  void parse_vertex() {
    ++p_;
    double xyz[3];
    for (int k = 0; k < 3; ++k) {
      skip_blanks();
      if (at_eol()) {
        fail("vertex has " + std::to_string(k) + " coordinate" + (k == 1 ? "" : "s") +
             "; expected 3 numbers (x y z)");
      }
      if (detail::parse_shaped(p_, end_, shapes_[k], xyz[k], p_)) continue;
      const char* start = p_;
      const char* first = detail::past_plus(p_, end_);
      auto [ptr, ec] = detail::parse_double(first, end_, xyz[k]);
      if (ec != std::errc() || ptr == first || !detail::ends_token(ptr, end_)) {
        fail("expected a number for the vertex's " + std::string(1, "xyz"[k]) +
             " coordinate, found " + quote_token(start, end_));
      }
      if (!std::isfinite(xyz[k])) {
        fail("vertex coordinate " + quote_token(start, end_) +
             " is not finite; expected a finite number");
      }
      p_ = ptr;
    }
    mesh_.positions.push_back({xyz[0], xyz[1], xyz[2]});
    skip_blanks();
    if (!at_eol() && *p_ != '#') check_vertex_extras();
  }

  /// What may follow a vertex's x y z: w, or a colour's r g b and maybe a, finite numbers that
  /// are read and not kept; anything else is an error, so that a line that runs on (a file
  /// whose lines end with a lone CR reads as one line) is not taken as one vertex.
  void check_vertex_extras() {
    static const std::string kExpected =
        "; expected x y z, then nothing, w, or a colour's r g b [a]";
    int extras = 0;
    for (; !at_eol() && *p_ != '#'; ++extras) {
      const char* start = p_;
      const char* first = detail::past_plus(p_, end_);
      double value = 0;
      auto [ptr, ec] = detail::parse_double(first, end_, value);
      if (extras == 4 || ec != std::errc() || ptr == first || !detail::ends_token(ptr, end_) ||
          !std::isfinite(value)) {
        const bool lone_cr = start[-1] == '\r';  // after "v x y z": never the text's start
        fail("unexpected " + quote_token(start, end_) + " after the vertex's coordinates" +
             kExpected + (lone_cr ? " (are the file's lines ended by a lone CR?)" : ""));
      }
      p_ = ptr;
      skip_blanks();
    }
    if (extras == 2) fail("vertex has 5 numbers" + kExpected);
  }

  /// The usual face line, "f A B C" with three positive indices of vertices already listed,
  /// each followed by a space and the last by the line's end: parsed here without the general
  /// loop's steps for signs, "/vt/vn" suffixes, comments and polygons (a 36K-triangle frame
  /// parsed in full on the 2-core EPYC: 1.67 -> 1.46 ms, its faces ~1.05 -> ~0.83). Anything
  /// else returns false with nothing consumed, and parse_face() reads the line as before.
  bool parse_plain_triangle() {
    const char* q = p_ + 1;
    const int64_t listed = static_cast<int64_t>(mesh_.positions.size());
    int32_t corner[3];
    for (int k = 0; k < 3; ++k) {
      if (q == end_ || *q != ' ') return false;
      while (q < end_ && *q == ' ') ++q;
      uint64_t shaped = 0;
      if (const char* after = detail::parse_shaped_index(q, end_, index_lengths_[k], shaped)) {
        if (shaped == 0 || shaped > static_cast<uint64_t>(listed)) return false;
        q = after;
        corner[k] = static_cast<int32_t>(shaped - 1);
        continue;
      }
      int64_t index = 0;
      const auto [after, ec] = detail::parse_integer(q, end_, index);
      if (ec != std::errc() || after == q || index <= 0 || index > listed) return false;
      q = after;
      corner[k] = static_cast<int32_t>(index - 1);
    }
    if (q < end_ && *q != '\n') return false;
    if (group_pending_) intern_group();
    mesh_.triangles.push_back({{corner[0], corner[1], corner[2]}});
    mesh_.source_polygon.push_back(static_cast<int32_t>(mesh_.polygon_count));
    mesh_.triangle_group.push_back(group_);
    ++mesh_.polygon_count;
    p_ = q;
    return true;
  }

  /// An index no frame can hold (vertex ids are 32-bit), whatever the file lists later.
  [[noreturn]] void index_past_any_count(const char* start) const {
    fail("vertex index " + quote_token(start, end_) + " is out of range; a frame holds at most " +
         std::to_string(std::numeric_limits<int32_t>::max()) + " vertices");
  }

  void parse_face() {
    if (parse_plain_triangle()) return;
    ++p_;
    corners_.clear();
    const int64_t listed = static_cast<int64_t>(mesh_.positions.size());
    for (;;) {
      skip_blanks();
      if (at_eol() || *p_ == '#') break;  // '#' starts a trailing comment
      const char* start = p_;
      const char* first = detail::past_plus(p_, end_);
      int64_t index = 0;
      auto [ptr, ec] = detail::parse_integer(first, end_, index);
      if (ec == std::errc::result_out_of_range) {
        if (*first == '-')
          fail("relative vertex index " + quote_token(start, end_) +
               " points before the first vertex (" + std::to_string(mesh_.positions.size()) +
               " vertices listed so far)");
        index_past_any_count(start);
      }
      if (ec != std::errc() || ptr == first ||
          (ptr < end_ && !is_blank_or_eol(*ptr) && *ptr != '/')) {
        fail("expected a vertex index (an integer, optionally followed by /vt/vn), found " +
             quote_token(start, end_));
      }
      p_ = ptr;
      // Texture and normal indices are not needed: pass over "/vt", "/vt/vn" or "//vn".
      while (p_ < end_ && !is_blank_or_eol(*p_)) ++p_;
      int64_t resolved;
      if (index > 0) {
        resolved = index - 1;
        if (resolved >= std::numeric_limits<int32_t>::max()) index_past_any_count(start);
        // OBJ lists vertices before the faces that use them in practice, but nothing forbids a
        // face naming a later vertex: check those once the whole file is read.
        if (resolved >= listed) forward_.push_back({line_, index, std::string(start, p_)});
      } else if (index < 0) {
        resolved = listed + index;
        if (resolved < 0) {
          fail("relative vertex index " + quote_token(start, end_) +
               " points before the first vertex (" + std::to_string(listed) +
               " vertices listed so far)");
        }
      } else {
        fail("vertex index " + quote_token(start, end_) + " is 0; OBJ indices start at 1");
      }
      corners_.push_back(static_cast<int32_t>(resolved));
    }
    if (corners_.size() < 3) {
      fail("face has " + std::to_string(corners_.size()) + " corner" +
           (corners_.size() == 1 ? "" : "s") + "; expected at least 3");
    }
    if (group_pending_) intern_group();
    const auto polygon = static_cast<int32_t>(mesh_.polygon_count);
    for (size_t j = 1; j + 1 < corners_.size(); ++j) {
      mesh_.triangles.push_back({{corners_[0], corners_[j], corners_[j + 1]}});
      mesh_.source_polygon.push_back(polygon);
      mesh_.triangle_group.push_back(group_);
    }
    ++mesh_.polygon_count;
  }

  /// A carriage return in the line before its last byte (CRLF's CR is its last): the file's
  /// lines end with a lone CR, and the rest of the file would be one long line to this reader
  /// (a comment, or a group's name, that hides every record after it).
  void refuse_lone_cr(const char* eol) {
    for (const char* cr = p_;
         (cr = static_cast<const char*>(std::memchr(cr, '\r', static_cast<size_t>(eol - cr))));
         ++cr)
      if (cr + 1 < eol)
        fail("a carriage return inside the line: are the file's lines ended by a lone CR?");
  }

  void parse_group() {
    ++p_;
    skip_blanks();
    const char* start = p_;
    const char* stop = detail::find_eol(p_, end_);
    refuse_lone_cr(stop);
    while (stop > start && is_blank(stop[-1])) --stop;
    pending_name_ = std::string_view(start, static_cast<size_t>(stop - start));
    // An empty `g` returns to the default group; a name is interned only when a face uses it,
    // so group_names holds names in order of first use.
    group_pending_ = !pending_name_.empty();
    if (!group_pending_) group_ = -1;
  }

  void intern_group() {
    auto [it, inserted] = group_ids_.try_emplace(std::string(pending_name_),
                                                 static_cast<int32_t>(mesh_.group_names.size()));
    if (inserted) mesh_.group_names.emplace_back(pending_name_);
    group_ = it->second;
    group_pending_ = false;
  }

  void check_forward_references() const {
    const auto count = static_cast<int64_t>(mesh_.positions.size());
    for (const ForwardReference& ref : forward_) {
      if (ref.index > count) {
        const std::string expected =
            count == 0 ? "the file has no vertex line"
                       : "the file has " + std::to_string(count) + " vertices (expected 1.." +
                             std::to_string(count) + " or -1..-" + std::to_string(count) + ")";
        throw InputError(name_, ref.line,
                         "vertex index '" + ref.token + "' is out of range; " + expected);
      }
    }
  }

  struct ForwardReference {
    int64_t line;
    int64_t index;
    std::string token;
  };

  const char* p_;
  const char* end_;
  const std::string& name_;
  int64_t line_ = 1;
  mesh::Mesh mesh_;
  std::vector<int32_t> corners_;    // reused for every face: no allocation per line
  detail::DecimalShape shapes_[3];  // the x, y and z columns' last layouts (parse_shaped)
  uint8_t index_lengths_[3] = {};   // plain triangles' corner columns (parse_shaped_index)
  std::vector<ForwardReference> forward_;
  std::string_view pending_name_;
  bool group_pending_ = false;
  int32_t group_ = -1;
  std::unordered_map<std::string, int32_t> group_ids_;
  detail::StructureCache* cache_;     // null: no reuse
  const char* tail_start_ = nullptr;  // after the last vertex line, if no face precedes it
  bool tail_pending_ = false;
  std::string_view tail_pending_name_;
};

}  // namespace

mesh::Mesh read_obj(std::string_view text, const std::string& name_for_errors) {
  return ObjParser(text, name_for_errors, nullptr).parse();
}

namespace detail {
mesh::Mesh read_obj_reusing(std::string_view text, const std::string& name_for_errors,
                            StructureCache& cache) {
  return ObjParser(text, name_for_errors, &cache).parse();
}
}  // namespace detail

mesh::Mesh read_obj_file(const std::filesystem::path& path) {
  return read_obj(detail::read_into_thread_buffer(path), path.string());
}

}  // namespace snag::io
