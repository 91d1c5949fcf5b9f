// Sequence resolution by directory listing: patterns and globs are matched against the names in
// one directory, never handed to a shell.
#include "snag/seq/sequence.h"

#include <algorithm>
#include <charconv>
#include <numeric>
#include <optional>
#include <system_error>

#include "snag/error.h"
#include "snag/io/read_mesh.h"

namespace snag::seq {
namespace fs = std::filesystem;

namespace {

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

bool is_frame_file_extension(const fs::path& p) {
  const std::string ext = io::lowercase_extension(p);
  return ext == ".obj" || ext == ".ply";
}

/// A file name split around its frame token.
struct FramePattern {
  std::string prefix;
  std::string suffix;
  int width = 1;  // printf's minimum width; 1 means unpadded
};

/// Finds the frame token in a file name. Returns nothing when there is none.
std::optional<FramePattern> find_frame_token(const std::string& name, const std::string& sequence) {
  std::optional<FramePattern> found;
  size_t i = 0;
  while (i < name.size()) {
    size_t start = i, stop = i;
    int width = 0;
    const char c = name[i];
    if (c == '%') {
      size_t j = i + 1;
      while (j < name.size() && is_digit(name[j])) ++j;
      if (j < name.size() && name[j] == 'd') {
        width = 1;
        if (j > i + 1) std::from_chars(name.data() + i + 1, name.data() + j, width);
        stop = j + 1;
      }
    } else if (c == '#' || c == '@') {
      size_t j = i;
      while (j < name.size() && name[j] == c) ++j;
      width = static_cast<int>(j - i);
      stop = j;
    } else if (c == '$' && i + 1 < name.size() && name[i + 1] == 'F') {
      size_t j = i + 2;
      while (j < name.size() && is_digit(name[j])) ++j;
      width = 1;
      if (j > i + 2) std::from_chars(name.data() + i + 2, name.data() + j, width);
      stop = j;
    }
    if (stop == start) {
      ++i;
      continue;
    }
    if (found) {
      throw UsageError(
          "sequence pattern '" + sequence +
          "' has more than one frame token; expected one of %04d, %d, ####, @, $F4 or $F (a "
          "glob such as hat#2.*.obj matches names that hold #, @, % or $F themselves)");
    }
    found = FramePattern{name.substr(0, start), name.substr(stop), std::max(width, 1)};
    i = stop;
  }
  if (found) {
    // The rest of the name is matched literally: reject what was probably meant as a glob.
    for (const std::string* part : {&found->prefix, &found->suffix}) {
      if (part->find_first_of("*?[") != std::string::npos) {
        throw UsageError("sequence pattern '" + sequence +
                         "' mixes a frame token with glob characters; use one or the other (in "
                         "a glob, [[], [*] and [?] match those characters themselves)");
      }
    }
  }
  return found;
}

/// The value of a run of digits; nothing when it does not fit in 64 bits.
std::optional<int64_t> frame_digits_value(std::string_view digits) {
  int64_t v = 0;
  auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (ec != std::errc() || ptr != digits.data() + digits.size()) return std::nullopt;
  return v;
}

int64_t parse_frame_digits(std::string_view digits, const std::string& path) {
  if (const std::optional<int64_t> v = frame_digits_value(digits)) return *v;
  throw InputError(path, 0, "frame number '" + std::string(digits) + "' does not fit in 64 bits");
}

/// The last run of decimal digits in `stem` (empty when there is none).
std::string_view last_digit_run(std::string_view stem) {
  size_t end = stem.size();
  while (end > 0 && !is_digit(stem[end - 1])) --end;
  size_t begin = end;
  while (begin > 0 && is_digit(stem[begin - 1])) --begin;
  return stem.substr(begin, end - begin);
}

/// What stands in `name` where the pattern's token is: the non-empty text between its prefix
/// and its suffix, or nothing when the name does not have them.
std::optional<std::string_view> token_text(std::string_view name, const FramePattern& pat) {
  if (name.size() <= pat.prefix.size() + pat.suffix.size() || !name.starts_with(pat.prefix) ||
      !name.ends_with(pat.suffix))
    return std::nullopt;
  return name.substr(pat.prefix.size(), name.size() - pat.prefix.size() - pat.suffix.size());
}

/// Matches `name` against the pattern; the frame number on success.
std::optional<int64_t> match_frame_pattern(const std::string& name, const FramePattern& pat,
                                           const std::string& path) {
  const std::optional<std::string_view> token = token_text(name, pat);
  if (!token) return std::nullopt;
  const std::string_view middle = *token;
  const bool negative = middle[0] == '-';
  const std::string_view digits = middle.substr(negative ? 1 : 0);
  if (digits.empty() || !std::all_of(digits.begin(), digits.end(), is_digit)) return std::nullopt;
  // printf writes leading zeros only to reach the width, and never shortens a number.
  const auto length = static_cast<int64_t>(middle.size());
  const bool zero_padded = digits.size() > 1 && digits[0] == '0';
  if (zero_padded ? length != pat.width : length < pat.width) return std::nullopt;
  const int64_t magnitude = parse_frame_digits(digits, path);
  return negative ? -magnitude : magnitude;
}

/// fnmatch-style matching of one path component: `*`, `?`, `[abc]`, `[a-z]`, `[!a]`/`[^a]`.
bool glob_match(std::string_view pattern, std::string_view name) {
  size_t p = 0, n = 0;
  size_t star_p = std::string_view::npos, star_n = 0;
  while (n < name.size()) {
    bool advanced = false;
    if (p < pattern.size()) {
      const char pc = pattern[p];
      if (pc == '*') {
        star_p = p++;
        star_n = n;
        continue;
      }
      if (pc == '?') {
        ++p;
        ++n;
        advanced = true;
      } else if (pc == '[') {
        size_t q = p + 1;
        bool negate = q < pattern.size() && (pattern[q] == '!' || pattern[q] == '^');
        if (negate) ++q;
        bool matched = false;
        size_t first = q;
        while (q < pattern.size() && (pattern[q] != ']' || q == first)) {
          if (q + 2 < pattern.size() && pattern[q + 1] == '-' && pattern[q + 2] != ']') {
            if (pattern[q] <= name[n] && name[n] <= pattern[q + 2]) matched = true;
            q += 3;
          } else {
            if (pattern[q] == name[n]) matched = true;
            ++q;
          }
        }
        if (q < pattern.size()) {  // a closed class
          if (matched != negate) {
            p = q + 1;
            ++n;
            advanced = true;
          }
        } else if (name[n] == '[') {  // an unclosed '[' is a literal
          ++p;
          ++n;
          advanced = true;
        }
      } else if (pc == name[n]) {
        ++p;
        ++n;
        advanced = true;
      }
    }
    if (advanced) continue;
    if (star_p == std::string_view::npos) return false;
    p = star_p + 1;
    n = ++star_n;
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

/// Regular files (symlinks followed) directly in `dir`, sorted by name, and links to nothing: a
/// frame whose link is broken is listed, so that reading it is the error that names it
/// instead of a frame left out in silence. Sorted, so that an error naming one of several
/// files names the same one on every filesystem.
std::vector<fs::path> list_files(const fs::path& dir, const std::string& sequence) {
  std::vector<fs::path> files;
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec);
  if (ec)
    throw InputError(sequence, 0, "cannot list directory '" + dir.string() + "': " + ec.message());
  for (const fs::directory_entry& entry : it) {
    std::error_code ignored;  // an entry whose type cannot be told is not listed
    const bool dangling = entry.is_symlink(ignored) && !fs::exists(entry.path(), ignored);
    if (entry.is_regular_file(ignored) || dangling)
      files.push_back(dir.empty() ? entry.path().filename() : entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// A directory's or a glob's files are numbered by the digits in their names: a file without
/// any among others would be frame 0 and come first, so that a rest pose or a stray export left
/// beside a cache would set the topology of the whole run. One file alone is frame 0.
void require_numbered_names(const std::vector<Frame>& frames, const std::string& sequence) {
  if (frames.size() < 2) return;
  for (const Frame& f : frames) {
    if (!last_digit_run(f.path.stem().string()).empty()) continue;
    // Appended rather than chained: GCC 12 warns falsely (-Wrestrict) on '"'" + string + ...'.
    std::string what = "'";
    what += f.path.string();
    what +=
        "' has no digits in its name to number it as a frame; each file of a directory or a "
        "glob is a frame numbered by the last digits in its name (move it away, or name the "
        "frames with a pattern such as dress.%04d.obj or a glob that leaves it out)";
    throw InputError(sequence, 0, what);
  }
}

/// When a pattern matched nothing: names a file that it would match at another width (the
/// pattern `drape.@.obj` against `drape.0001.obj`), and the token that matches it.
std::string other_width_hint(const fs::path& dir, const FramePattern& pattern,
                             const std::string& sequence) {
  for (const fs::path& file : list_files(dir, sequence)) {
    const std::string name = file.filename().string();
    const std::optional<std::string_view> digits = token_text(name, pattern);
    if (!digits || !std::all_of(digits->begin(), digits->end(), is_digit)) continue;
    std::string hint = "; '";
    hint += name;
    if (digits->size() > 1 && digits->front() == '0') {
      const std::string width = std::to_string(digits->size());
      hint += "' has its frame number padded to " + width + " digits: write %0" + width + "d, " +
              std::string(digits->size(), '#') + " or $F" + width;
    } else {
      hint += "' has its frame number unpadded: write %d, # or $F";
    }
    return hint;
  }
  return {};
}

std::vector<Frame> sorted_unique(std::vector<Frame> frames, const std::string& sequence) {
  std::sort(frames.begin(), frames.end(), [](const Frame& a, const Frame& b) {
    return a.number != b.number ? a.number < b.number : a.path < b.path;
  });
  for (size_t i = 1; i < frames.size(); ++i) {
    if (frames[i].number == frames[i - 1].number) {
      throw InputError(sequence, 0,
                       "two files have frame number " + std::to_string(frames[i].number) + ": '" +
                           frames[i - 1].path.string() + "' and '" + frames[i].path.string() +
                           "'; expected one file per frame (name a pattern to pick one set)");
    }
  }
  return frames;
}

}  // namespace

int64_t frame_number_from_name(const fs::path& path) {
  const std::string stem = path.stem().string();
  const std::string_view digits = last_digit_run(stem);
  return digits.empty() ? 0 : parse_frame_digits(digits, path.string());
}

std::vector<Frame> resolve_sequence(const std::string& sequence) {
  if (sequence.empty())
    throw UsageError(
        "the sequence argument is empty; expected a file, a directory, a pattern or a glob");
  const fs::path spec(sequence);
  std::error_code ec;
  const fs::file_status status = fs::status(spec, ec);
  if (fs::is_directory(status)) {
    std::vector<Frame> frames;
    for (const fs::path& file : list_files(spec, sequence)) {
      if (is_frame_file_extension(file)) frames.push_back({frame_number_from_name(file), file});
    }
    if (frames.empty()) throw InputError(sequence, 0, "directory has no .obj or .ply files");
    require_numbered_names(frames, sequence);
    return sorted_unique(std::move(frames), sequence);
  }
  if (fs::exists(status)) {
    // One file: its number only labels the reports, and a name whose digits do not fit in 64
    // bits (a timestamp to the microsecond, say) is still a file to check: frame 0, as a name
    // without digits. Frames of a sequence need theirs to be put in order.
    const std::string stem = spec.stem().string();
    const std::string_view digits = last_digit_run(stem);
    return {{digits.empty() ? 0 : frame_digits_value(digits).value_or(0), spec}};
  }

  const fs::path dir = spec.parent_path();
  const std::string name = spec.filename().string();
  const std::optional<FramePattern> pattern = find_frame_token(name, sequence);
  const bool is_glob = !pattern && name.find_first_of("*?[") != std::string::npos;
  if (!pattern && !is_glob) {
    throw InputError(
        sequence, 0,
        "no such file or directory; expected a file, a directory, a pattern with %04d, "
        "####, @ or $F4, or a glob");
  }
  if (!dir.empty() && !fs::is_directory(dir, ec)) {
    throw InputError(sequence, 0, "directory '" + dir.string() + "' does not exist");
  }
  std::vector<Frame> frames;
  for (const fs::path& file : list_files(dir, sequence)) {
    const std::string file_name = file.filename().string();
    if (pattern) {
      if (auto number = match_frame_pattern(file_name, *pattern, file.string()))
        frames.push_back({*number, file});
    } else if (glob_match(name, file_name)) {
      frames.push_back({frame_number_from_name(file), file});
    }
  }
  if (frames.empty()) {
    throw InputError(sequence, 0,
                     std::string("no files match the ") + (pattern ? "pattern" : "glob") + " in '" +
                         (dir.empty() ? std::string(".") : dir.string()) + "'" +
                         (pattern ? other_width_hint(dir, *pattern, sequence) : std::string()));
  }
  if (!pattern) require_numbered_names(frames, sequence);
  return sorted_unique(std::move(frames), sequence);
}

FrameSelection FrameSelection::parse(std::string_view text) {
  FrameSelection sel;
  sel.text_ = std::string(text);
  sel.all_ = false;
  const std::string expected =
      "; expected N, FIRST-LAST or FIRST-LASTxSTEP, separated by commas (e.g. 1-240x5,300)";
  auto trim = [](std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
  };
  size_t pos = 0;
  for (;;) {
    const size_t comma = text.find(',', pos);
    const std::string_view item =
        trim(text.substr(pos, comma == std::string_view::npos ? text.npos : comma - pos));
    std::string quoted = "'";  // appended: GCC 12 warns falsely (-Wrestrict) on the chain
    quoted += item;
    quoted += '\'';
    if (item.empty())
      throw UsageError("frame selection '" + std::string(text) + "' has an empty item" + expected);
    const char* p = item.data();
    const char* end = item.data() + item.size();
    auto number = [&](int64_t& out) {
      auto [ptr, ec] = std::from_chars(p, end, out);
      if (ec != std::errc()) {
        throw UsageError("frame selection item " + quoted + " has a bad number at '" +
                         std::string(p, end) + "'" + expected);
      }
      p = ptr;
    };
    Range r{0, 0, 1};
    number(r.first);
    r.last = r.first;
    if (p < end && *p == '-') {
      ++p;
      number(r.last);
      if (p < end && *p == 'x') {
        ++p;
        number(r.step);
        if (r.step <= 0)
          throw UsageError("frame selection item " + quoted + " has step " +
                           std::to_string(r.step) + "; expected a step of 1 or more");
      }
    }
    if (p != end) {
      throw UsageError("frame selection item " + quoted + " has unexpected '" +
                       std::string(p, end) + "'" + expected);
    }
    if (r.last < r.first) {
      throw UsageError("frame selection item " + quoted +
                       " ends before it starts; expected FIRST <= LAST");
    }
    sel.ranges_.push_back(r);
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  return sel;
}

bool FrameSelection::contains(int64_t frame) const {
  if (all_) return true;
  for (const Range& r : ranges_) {
    // Unsigned difference: last - first cannot overflow for any pair of int64 frame numbers.
    if (frame >= r.first && frame <= r.last &&
        (static_cast<uint64_t>(frame) - static_cast<uint64_t>(r.first)) %
                static_cast<uint64_t>(r.step) ==
            0) {
      return true;
    }
  }
  return false;
}

std::vector<std::string> FrameSelection::absent_runs(const std::vector<Frame>& frames,
                                                     size_t most_runs, bool* more) const {
  std::vector<std::string> runs;
  if (more) *more = false;
  if (all_) return runs;
  // A run of the item's numbers from `from` to `to` (both on its grid), when there is one.
  const auto add_run = [&](int64_t from, int64_t to, int64_t step) {
    if (from > to) return;
    const bool full = runs.size() >= most_runs;
    if (full && (!more || *more)) return;  // nothing left to learn
    std::string run = std::to_string(from);
    if (to != from) (run += '-') += std::to_string(to);
    if (to != from && step != 1) (run += 'x') += std::to_string(step);
    if (std::find(runs.begin(), runs.end(), run) != runs.end()) return;  // named once
    if (full)
      *more = true;
    else
      runs.push_back(run);
  };
  for (const Range& r : ranges_) {
    const auto step = static_cast<uint64_t>(r.step);
    // The item's next number not yet accounted for; unsigned, as in contains(): the grid's
    // numbers and their differences fit in 64 bits even where int64 sums would overflow.
    uint64_t next = static_cast<uint64_t>(r.first);
    bool done = false;
    for (const Frame& f : frames) {
      if (f.number < r.first) continue;
      if (f.number > r.last) break;
      const uint64_t offset = static_cast<uint64_t>(f.number) - static_cast<uint64_t>(r.first);
      if (offset % step != 0) continue;
      if (static_cast<uint64_t>(f.number) != next)
        add_run(static_cast<int64_t>(next),
                static_cast<int64_t>(static_cast<uint64_t>(f.number) - step), r.step);
      if (static_cast<uint64_t>(r.last) - static_cast<uint64_t>(f.number) < step) {
        // The item's last number: nothing after it.
        done = true;
        break;
      }
      next = static_cast<uint64_t>(f.number) + step;
    }
    if (!done) {
      // The item's last number on its grid, from its first.
      const uint64_t span = static_cast<uint64_t>(r.last) - static_cast<uint64_t>(r.first);
      add_run(static_cast<int64_t>(next),
              static_cast<int64_t>(static_cast<uint64_t>(r.first) + span / step * step), r.step);
    }
  }
  return runs;
}

FrameGaps frame_gaps(const std::vector<Frame>& frames, size_t most_runs) {
  FrameGaps gaps;
  if (frames.size() < 3) return gaps;
  // The differences fit in 64 bits unsigned whatever the numbers (as in absent_runs).
  uint64_t step = 0;
  for (size_t i = 1; i < frames.size(); ++i)
    step = std::gcd(step, static_cast<uint64_t>(frames[i].number) -
                              static_cast<uint64_t>(frames[i - 1].number));
  gaps.first = frames.front().number;
  gaps.last = frames.back().number;
  // Three distinct numbers spanning less than 2^64 have a divisor of their differences below
  // 2^63: the step is an int64.
  gaps.step = static_cast<int64_t>(step);
  const FrameSelection grid = FrameSelection::parse(
      std::to_string(gaps.first) + "-" + std::to_string(gaps.last) + "x" + std::to_string(step));
  gaps.runs = grid.absent_runs(frames, most_runs, &gaps.more);
  return gaps;
}

std::vector<Frame> select_frames(const std::vector<Frame>& frames,
                                 const FrameSelection& selection) {
  std::vector<Frame> kept;
  for (const Frame& f : frames) {
    if (selection.contains(f.number)) kept.push_back(f);
  }
  if (kept.empty() && !frames.empty()) {
    const auto [lo, hi] =
        std::minmax_element(frames.begin(), frames.end(),
                            [](const Frame& a, const Frame& b) { return a.number < b.number; });
    throw UsageError("frame selection '" + selection.text() + "' keeps none of the " +
                     std::to_string(frames.size()) + " frames (numbered " +
                     std::to_string(lo->number) + " to " + std::to_string(hi->number) + ")");
  }
  return kept;
}

}  // namespace snag::seq
