// Small helpers shared by the text readers (OBJ, ascii PLY): character classes and quoting the
// offending token in error messages. Private to lib/src/io.
#pragma once

#include <fast_float/fast_float.h>

#include <charconv>
#include <cstddef>
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

/// The ASCII digits from `p` on, at most `most` of them and none at or past `end`, appended to
/// `value` (value * 10 + digit each); returns where they stop. One bound for both the text's
/// end and the count: a compare a digit fewer, and the caller's counts come from the pointers
/// (a coordinate digit's step was fourteen instructions with three counters, now nine).
inline const char* append_digits(const char* p, const char* end, std::ptrdiff_t most,
                                 uint64_t& value) {
  const char* const limit = end - p > most ? p + most : end;
  for (; p < limit && static_cast<unsigned char>(*p - '0') < 10; ++p)
    value = value * 10 + static_cast<unsigned>(*p - '0');
  return p;
}

/// std::from_chars for an integer (an index, a count), with a plain digit loop for the usual
/// case of at most 18 digits (no overflow possible), which is about twice as fast.
inline std::from_chars_result parse_integer(const char* first, const char* end, int64_t& value) {
  uint64_t v = 0;
  const char* const q = append_digits(first, end, 18, v);
  if (q > first && (q == end || static_cast<unsigned char>(*q - '0') >= 10)) {
    value = static_cast<int64_t>(v);
    return {q, std::errc()};
  }
  return std::from_chars(first, end, value);
}

/// fast_float::from_chars for a coordinate, with a path of its own for the usual token: an
/// optional '-', digits with at most one '.', 15 digits at most, then the token's end (a blank,
/// a line end or the end of the text). Such a token is m / 10^k with m < 10^15 < 2^53 and k <=
/// 15, both exact doubles, so one correctly rounded division gives the correctly rounded value
/// (Clinger's fast path), bit for bit fast_float's; any other token goes to fast_float, so what
/// is accepted and rejected does not change. About 7 ns a coordinate where fast_float took 12
/// (a 36K-triangle OBJ frame's 55K coordinates on the 2-core EPYC: 0.65 -> 0.37 ms).
inline fast_float::from_chars_result parse_double(const char* first, const char* end,
                                                  double& value) {
  static constexpr double kPowersOfTen[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                            1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  const char* q = first;
  const bool negative = q < end && *q == '-';
  q += negative;
  // At most 16 digits are read in all, one more than the path takes.
  uint64_t mantissa = 0;
  const char* const whole_begin = q;
  q = append_digits(q, end, 16, mantissa);
  int digits = static_cast<int>(q - whole_begin), fraction = 0;
  if (q < end && *q == '.') {
    const char* const fraction_begin = q + 1;
    q = append_digits(fraction_begin, end, 16 - digits, mantissa);
    fraction = static_cast<int>(q - fraction_begin);
    digits += fraction;
  }
  if (digits == 0 || digits > 15 || !ends_token(q, end))
    return fast_float::from_chars(first, end, value);
  const double magnitude = static_cast<double>(mantissa) / kPowersOfTen[fraction];
  value = negative ? -magnitude : magnitude;
  return {q, std::errc()};
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
