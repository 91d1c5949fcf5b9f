#include "snag/report/baseline.h"

#include <algorithm>
#include <charconv>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "snag/error.h"
#include "snag/io/read_mesh.h"

namespace snag::report {

namespace {

/// The records of a CSV text (RFC 4180, as csv_field writes fields): fields split at commas, a
/// quoted field may hold commas, line breaks and doubled quotes; "\n" or "\r\n" ends a record.
class CsvRecords {
 public:
  CsvRecords(std::string_view text, const std::string& name) : text_(text), name_(name) {
    // A spreadsheet that saved the file may have put a byte order mark in front.
    if (text_.starts_with("\xEF\xBB\xBF")) at_ = 3;
  }

  /// The next record's fields into `fields` (their capacity kept); false after the last. Blank
  /// lines are passed over.
  bool next(std::vector<std::string>& fields) {
    while (at_ < text_.size()) {
      record_line_ = line_;
      size_t count = 0;
      for (;;) {
        if (count == fields.size()) fields.emplace_back();
        std::string& field = fields[count++];
        field.clear();
        const bool end = read_field(field);
        if (end) break;
      }
      fields.resize(count);
      if (count == 1 && fields[0].empty() && !last_field_quoted_) continue;  // a blank line
      return true;
    }
    return false;
  }

  /// The line the last record began on (1-based).
  int64_t line() const { return record_line_; }

 private:
  /// Reads one field into `field`; true when it ended its record (a line end or the text's).
  bool read_field(std::string& field) {
    // Spaces and tabs typed around a value ("frame, face_a", `1, "a, b" ,2`) are not part of it.
    const auto skip_blanks = [&] {
      while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\t')) ++at_;
    };
    const size_t start = at_;
    skip_blanks();
    last_field_quoted_ = at_ < text_.size() && text_[at_] == '"';
    if (!last_field_quoted_) at_ = start;
    if (last_field_quoted_) {
      ++at_;
      for (;;) {
        if (at_ == text_.size())
          throw InputError(name_, record_line_, "a quoted field is not closed");
        const char c = text_[at_++];
        if (c == '"') {
          if (at_ < text_.size() && text_[at_] == '"') {
            field += '"';
            ++at_;
            continue;
          }
          break;
        }
        if (c == '\n') ++line_;
        field += c;
      }
      skip_blanks();
    } else {
      const size_t end = text_.find_first_of(",\r\n\"", at_);
      const size_t stop = end == std::string_view::npos ? text_.size() : end;
      std::string_view value = text_.substr(at_, stop - at_);
      while (!value.empty() && (value.front() == ' ' || value.front() == '\t'))
        value.remove_prefix(1);
      while (!value.empty() && (value.back() == ' ' || value.back() == '\t'))
        value.remove_suffix(1);
      field.append(value);
      at_ = stop;
      if (at_ < text_.size() && text_[at_] == '"')
        throw InputError(name_, line_, "a quote inside an unquoted field (quote the whole field)");
    }
    if (at_ == text_.size()) return true;
    const char c = text_[at_];
    if (c == ',') {
      ++at_;
      return false;
    }
    if (c == '\r' && at_ + 1 < text_.size() && text_[at_ + 1] == '\n') ++at_;
    if (text_[at_] == '\n') {
      ++at_;
      ++line_;
      return true;
    }
    throw InputError(name_, line_,
                     c == '\r' ? "a carriage return not followed by a line feed"
                               : "text after a quoted field's closing quote");
  }

  std::string_view text_;
  const std::string& name_;
  size_t at_ = 0;
  int64_t line_ = 1;
  int64_t record_line_ = 1;
  bool last_field_quoted_ = false;
};

/// `text` as a whole number of type T, nothing else in it; nullopt otherwise.
template <class T>
std::optional<T> whole_number(const std::string& text) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc{} || stop != end || text.empty()) return std::nullopt;
  return value;
}

std::string in_quotes(const std::string& text) {
  return "'" + text + "'";
}

/// The columns a baseline is read by (header positions; -1 when absent).
struct Columns {
  int frame = -1, face_a = -1, face_b = -1, kind = -1, object_a = -1, object_b = -1, accepted = -1;
};

/// The header's fields joined as they were read, for a message about it.
std::string header_text(const std::vector<std::string>& header) {
  std::string text;
  for (const std::string& field : header) text += (text.empty() ? "" : ",") + field;
  return text;
}

Columns columns_of(const std::vector<std::string>& header, const std::string& name, int64_t line,
                   bool scene) {
  Columns c;
  const std::pair<const char*, int*> wanted[] = {
      {"frame", &c.frame},      {"face_a", &c.face_a},     {"face_b", &c.face_b},
      {"kind", &c.kind},        {"object_a", &c.object_a}, {"object_b", &c.object_b},
      {"accepted", &c.accepted}};
  for (int i = 0; i < static_cast<int>(header.size()); ++i)
    for (const auto& [column, at] : wanted)
      if (header[i] == column) {
        if (*at >= 0)
          throw InputError(name, line, std::string("the header names column ") + column + " twice");
        *at = i;
      }
  for (const auto& [column, at] : {wanted[0], wanted[1], wanted[2]})
    if (*at < 0)
      throw InputError(name, line,
                       std::string("no ") + column + " column in the header " +
                           in_quotes(header_text(header)) +
                           ": a baseline is a pairs.csv, comma-separated, its header "
                           "frame,face_a,face_b,kind,... (the columns in any order)");
  const bool objects_named = c.object_a >= 0 || c.object_b >= 0;
  if (objects_named && (c.object_a < 0 || c.object_b < 0))
    throw InputError(name, line,
                     std::string("column ") + (c.object_a < 0 ? "object_b" : "object_a") +
                         " without " + (c.object_a < 0 ? "object_a" : "object_b"));
  if (scene && !objects_named)
    throw InputError(name, line,
                     "no object_a and object_b columns, but this run checks several objects: "
                     "a baseline for it names each face's object, as its pairs.csv does");
  if (!scene && objects_named)
    throw InputError(name, line,
                     "object_a and object_b columns, but this run checks one mesh (is it the "
                     "pairs.csv of a run with --obstacle, --scene or --split-groups?)");
  return c;
}

}  // namespace

Baseline Baseline::read(const std::filesystem::path& path, std::span<const ObjectInput> objects) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw InputError(path.string(), 0, "a directory; expected a pairs.csv file");
  return parse(io::read_file_bytes(path), path.string(), objects);
}

Baseline Baseline::parse(std::string_view text, const std::string& name,
                         std::span<const ObjectInput> objects) {
  CsvRecords records(text, name);
  std::vector<std::string> fields;
  if (!records.next(fields))
    throw InputError(name, 0, "empty: a baseline is a pairs.csv, its header first");
  const int64_t header_line = records.line();
  const Columns c = columns_of(fields, name, header_line, !objects.empty());
  // Optional columns past a row's end are empty: a row cut by hand may stop before them.
  const size_t needed =
      static_cast<size_t>(std::max({c.frame, c.face_a, c.face_b, c.object_a, c.object_b})) + 1;
  const auto optional_field = [&](int column) -> const std::string& {
    static const std::string empty;
    return column >= 0 && static_cast<size_t>(column) < fields.size() ? fields[column] : empty;
  };
  std::unordered_map<std::string, int32_t> object_index;
  for (size_t i = 0; i < objects.size(); ++i)
    object_index.emplace(objects[i].name, static_cast<int32_t>(i));

  Baseline baseline;
  baseline.name_ = name;
  baseline.whole_file_.assign(std::max<size_t>(objects.size(), 1), true);
  for (size_t i = 0; i < objects.size(); ++i) {
    baseline.whole_file_[i] = !objects[i].group;
    baseline.object_names_.push_back(objects[i].name);
  }
  std::vector<Entry> every_frame;
  while (records.next(fields)) {
    const int64_t line = records.line();
    if (fields.size() < needed)
      throw InputError(name, line,
                       "only " + std::to_string(fields.size()) +
                           " fields; the header's frame, face and object columns need " +
                           std::to_string(needed));
    const std::string& accepted = optional_field(c.accepted);
    if (accepted == "0") {
      ++baseline.left_out_;
      continue;
    }
    if (accepted != "1" && !accepted.empty())
      throw InputError(name, line,
                       "accepted: expected 1, 0 or nothing, got " + in_quotes(accepted));
    const auto face = [&](int column, const char* what) {
      const std::optional<int32_t> id = whole_number<int32_t>(fields[column]);
      if (!id || *id < 0)
        throw InputError(name, line,
                         std::string(what) + ": expected a face id (a whole number >= 0), got " +
                             in_quotes(fields[column]));
      return *id;
    };
    const auto object = [&](int column, const char* what) -> int32_t {
      if (column < 0) return 0;
      const auto found = object_index.find(fields[column]);
      if (found == object_index.end()) {
        std::string names;
        for (const ObjectInput& o : objects) names += (names.empty() ? "" : ", ") + o.name;
        throw InputError(name, line,
                         std::string(what) + ": " + in_quotes(fields[column]) +
                             " is not an object of this run (" + names + ")");
      }
      return found->second;
    };
    Entry e;
    e.line = line;
    const std::string& frame = fields[c.frame];
    const bool every = frame == "*";
    if (!every) {
      const std::optional<int64_t> number = whole_number<int64_t>(frame);
      if (!number)
        throw InputError(
            name, line,
            "frame: expected a frame number or * (every frame), got " + in_quotes(frame));
      e.frame = *number;
    }
    e.a = face(c.face_a, "face_a");
    e.b = face(c.face_b, "face_b");
    e.object_a = object(c.object_a, "object_a");
    e.object_b = object(c.object_b, "object_b");
    if (std::tie(e.object_b, e.b) < std::tie(e.object_a, e.a)) {
      std::swap(e.object_a, e.object_b);
      std::swap(e.a, e.b);
    }
    if (e.object_a == e.object_b && e.a == e.b)
      throw InputError(name, line,
                       "face " + std::to_string(e.a) + " paired with itself (face_a = face_b)");
    const std::string& kind = optional_field(c.kind);
    if (kind == "touching")
      e.crossing_accepted = false;
    else if (kind != "crossing" && kind != "*" && !kind.empty())
      throw InputError(name, line,
                       "kind: expected crossing, touching or * (either), got " + in_quotes(kind));
    (every ? every_frame : baseline.entries_).push_back(e);
  }

  // Sorted, and a pair listed twice made one entry that accepts what either row accepts.
  const auto key = [](const Entry& e) {
    return std::tie(e.frame, e.object_a, e.a, e.object_b, e.b);
  };
  const auto merge = [&](std::vector<Entry>& entries) {
    std::sort(entries.begin(), entries.end(),
              [&](const Entry& x, const Entry& y) { return key(x) < key(y); });
    size_t kept = 0;
    for (size_t i = 0; i < entries.size(); ++i) {
      if (kept > 0 && key(entries[kept - 1]) == key(entries[i])) {
        entries[kept - 1].crossing_accepted |= entries[i].crossing_accepted;
        entries[kept - 1].line = std::min(entries[kept - 1].line, entries[i].line);
        continue;
      }
      entries[kept++] = entries[i];
    }
    entries.resize(kept);
  };
  merge(baseline.entries_);
  merge(every_frame);  // their frames are all 0: sorted by the pair alone
  baseline.every_frame_begin_ = baseline.entries_.size();
  baseline.entries_.insert(baseline.entries_.end(), every_frame.begin(), every_frame.end());
  return baseline;
}

void Baseline::mark(FrameRecord& frame) {
  const auto per_frame_end = entries_.begin() + static_cast<std::ptrdiff_t>(every_frame_begin_);
  const auto first =
      std::lower_bound(entries_.begin(), per_frame_end, frame.frame,
                       [](const Entry& e, int64_t number) { return e.frame < number; });
  const auto last =
      std::upper_bound(first, per_frame_end, frame.frame,
                       [](int64_t number, const Entry& e) { return number < e.frame; });
  // An entry's faces must be faces of the frame it is for, where their count is known; an
  // every-frame entry is held to the frames up to the first whose face list changed (its ids
  // were found in one face list, and a later one may have fewer faces).
  face_list_changed_ = face_list_changed_ || frame.topology_changed;
  const auto triangles_of = [&](int32_t object) -> int64_t {
    if (static_cast<size_t>(object) >= whole_file_.size() || !whole_file_[object]) return -1;
    if (frame.objects.empty()) return object == 0 ? frame.triangles : -1;
    return static_cast<size_t>(object) < frame.objects.size() ? frame.objects[object].triangles
                                                              : -1;
  };
  const auto check = [&](Entry& e, bool bounded) {
    e.checked = true;
    if (!bounded) return;
    for (const auto& [object, face] : {std::pair{e.object_a, e.a}, std::pair{e.object_b, e.b}})
      if (const int64_t count = triangles_of(object); count >= 0 && face >= count)
        throw InputError(name_, e.line,
                         "face " + std::to_string(face) + " is not a face of frame " +
                             std::to_string(frame.frame) + " (" +
                             (frame.objects.empty() ? "" : object_names_[object] + ": ") +
                             std::to_string(count) + (count == 1 ? " triangle" : " triangles") +
                             "): is the baseline for another mesh?");
  };
  for (auto e = first; e != last; ++e) check(*e, true);
  for (auto e = per_frame_end; e != entries_.end(); ++e) check(*e, !face_list_changed_);
  // The entry of `pair` in [begin, end) (sorted by pair), if it accepts the pair as it is now.
  const auto accepts = [](auto begin, auto end, const Pair& p) {
    auto object_a = p.object_a, a = p.a, object_b = p.object_b, b = p.b;
    if (std::tie(object_b, b) < std::tie(object_a, a)) {
      std::swap(object_a, object_b);
      std::swap(a, b);
    }
    const auto wanted = std::tie(object_a, a, object_b, b);
    const auto at = std::lower_bound(begin, end, wanted, [](const Entry& e, const auto& w) {
      return std::tie(e.object_a, e.a, e.object_b, e.b) < w;
    });
    if (at == end || std::tie(at->object_a, at->a, at->object_b, at->b) != wanted) return false;
    if (p.kind == detect::PairKind::crossing && !at->crossing_accepted) return false;
    at->matched = true;
    return true;
  };
  for (Pair& p : frame.pairs) {
    // Both looked up, so that each entry that accepts the pair counts as matched.
    const bool in_frame = accepts(first, last, p);
    const bool in_every_frame = accepts(per_frame_end, entries_.end(), p);
    p.accepted = in_frame || in_every_frame;
  }
}

BaselineUse Baseline::use() const {
  BaselineUse use;
  use.entries = entries();
  use.left_out = left_out_;
  for (const Entry& e : entries_) {
    use.checked += e.checked;
    if (e.checked && !e.matched) use.unmatched_lines.push_back(e.line);
  }
  use.unmatched = static_cast<int64_t>(use.unmatched_lines.size());
  std::sort(use.unmatched_lines.begin(), use.unmatched_lines.end());
  return use;
}

}  // namespace snag::report
