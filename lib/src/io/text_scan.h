// Small helpers shared by the text readers (OBJ, ascii PLY): character classes and quoting the
// offending token in error messages. Private to lib/src/io.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>

namespace snag::io::detail {

/// Blanks inside a line. '\r' counts as one so that CRLF files need no special case.
inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
inline bool is_blank_or_eol(char c) {
  return is_blank(c) || c == '\n';
}

/// The next '\n' at or after `p`, or `end`.
inline const char* find_eol(const char* p, const char* end) {
  if (p >= end) return end;
  const void* nl = std::memchr(p, '\n', static_cast<size_t>(end - p));
  return nl ? static_cast<const char*>(nl) : end;
}

/// Where a number's parse starts in the token at `p`: past a leading '+' (which some writers
/// emit, and which std::from_chars and fast_float reject), unless a sign follows it.
inline const char* past_plus(const char* p, const char* end) {
  return (*p == '+' && p + 1 < end && p[1] != '-') ? p + 1 : p;
}

/// Whether a number parsed up to `ptr` is its whole token: what follows it is a blank, a line
/// end or the end of the text.
inline bool ends_token(const char* ptr, const char* end) {
  return ptr == end || is_blank_or_eol(*ptr);
}

/// std::from_chars for an integer (an index, a count), with a plain digit loop for the usual
/// case of at most 18 digits (no overflow possible), which is about twice as fast.
inline std::from_chars_result parse_integer(const char* first, const char* end, int64_t& value) {
  const char* q = first;
  uint64_t v = 0;
  while (q < end && q - first < 18 && static_cast<unsigned char>(*q - '0') < 10) {
    v = v * 10 + static_cast<unsigned>(*q - '0');
    ++q;
  }
  if (q > first && (q == end || static_cast<unsigned char>(*q - '0') >= 10)) {
    value = static_cast<int64_t>(v);
    return {q, std::errc()};
  }
  return std::from_chars(first, end, value);
}

/// The whitespace-delimited token starting at `p`, quoted, shortened past 40 characters so that
/// a binary file read as text does not flood the message.
inline std::string quote_token(const char* p, const char* end) {
  const char* q = p;
  while (q < end && !is_blank_or_eol(*q) && q - p < 40) ++q;
  if (q == p) return p == end ? "end of file" : "end of line";
  std::string s;
  s.reserve(static_cast<size_t>(q - p) + 5);
  s += '\'';
  s.append(p, q);
  if (q < end && !is_blank_or_eol(*q)) s += "...";
  s += '\'';
  return s;
}

}  // namespace snag::io::detail
