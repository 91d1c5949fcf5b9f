// Small helpers shared by the text readers (OBJ, ascii PLY): character classes and quoting the
// offending token in error messages. Private to lib/src/io.
#pragma once

#include <fast_float/fast_float.h>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/// The layout of a plain decimal token, [-]W[.F] (W and F runs of digits): how parse_shaped
/// expects the next token of a column to look, as masks over the 16 bytes after the sign. A
/// writer prints a column in one format ("%f": -1.131931), so the layout of the last token is
/// nearly always that of the next, and the token's end is known before its bytes are looked
/// at: the next token's parse does not wait for this one's (a byte loop's end, or a mask's
/// first non-digit, is a chain of dependent steps that it would wait for).
struct DecimalShape {
  uint32_t window = 0;  ///< the token's bytes and the one after it
  uint32_t digits = 0;  ///< which of them are digits
  uint32_t dot = 0;     ///< the '.', when there is one
  uint8_t whole = 0, fraction = 0, length = 0;
  bool known = false;
};

/// Eight or fewer ASCII digits as a number: `chunk` holds them from its lowest byte on, `count`
/// of them (1 to 8), whatever follows. SWAR: the digits shifted to the top bytes (the bytes
/// below are zero digits), then pairs, fours and eights combined by multiplications.
inline uint64_t eight_digits_value(uint64_t chunk, int count) {
  uint64_t v = (chunk - 0x3030303030303030ull) << (8 * (8 - count));
  v = v * 10 + (v >> 8);  // each even byte: two digits' value (the odd bytes are junk)
  v = (((v & 0x000000ff000000ffull) * (100 + (1000000ull << 32))) +
       (((v >> 16) & 0x000000ff000000ffull) * (1 + (10000ull << 32)))) >>
      32;
  return v;
}

/// parse_double's plain path for a token laid out as `shape` says, read without a loop: the
/// bytes' classes (digit, '.', blank or line end) as bit masks from one 16-byte load, compared
/// with the shape's; the digits' value from two 8-byte loads. When the token is not so laid out
/// but is a plain decimal of up to 8 + 8 digits that fits in the 16 bytes, `shape` becomes its
/// layout and it is read the same way. Returns false, with nothing changed but `shape`, for any
/// other token or when fewer than 18 bytes are left (the loads reach 17 bytes past a sign);
/// then parse_double decides. On true, `value` is parse_double's value bit for bit (the same
/// mantissa divided by the same power of ten) and `after` the token's end, which is followed
/// by a blank or a line end.
inline bool parse_shaped(const char* first, const char* end, DecimalShape& shape, double& value,
                         const char*& after) {
#if defined(__SSE2__)
  static constexpr double kPowersOfTen[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8};
  static constexpr uint64_t kPowers[] = {1,      10,      100,      1000,     10000,
                                         100000, 1000000, 10000000, 100000000};
  if (end - first < 18) return false;
  const bool negative = *first == '-';
  const char* const q = first + negative;
  const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
  const __m128i less_zero = _mm_sub_epi8(bytes, _mm_set1_epi8('0'));
  const auto digit = static_cast<uint32_t>(
      _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_min_epu8(less_zero, _mm_set1_epi8(9)), less_zero)));
  const auto dot =
      static_cast<uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(bytes, _mm_set1_epi8('.'))));
  // is_blank_or_eol: ' ', or '\t' '\n' '\v' '\f' '\r' (9 to 13).
  const __m128i less_tab = _mm_sub_epi8(bytes, _mm_set1_epi8('\t'));
  const auto blank = static_cast<uint32_t>(_mm_movemask_epi8(
      _mm_or_si128(_mm_cmpeq_epi8(bytes, _mm_set1_epi8(' ')),
                   _mm_cmpeq_epi8(_mm_min_epu8(less_tab, _mm_set1_epi8(4)), less_tab))));
  if (!shape.known || (digit & shape.window) != shape.digits || (dot & shape.window) != shape.dot ||
      !((blank >> shape.length) & 1)) {
    // Another layout: this token's own, if it is a plain decimal that fits.
    const int whole = __builtin_ctz(~digit);
    const int has_dot = (dot >> whole) & 1;
    const int fraction = has_dot ? __builtin_ctz(~(digit >> (whole + 1))) : 0;
    const int length = whole + has_dot + fraction;
    if (whole > 8 || fraction > 8 || whole + fraction == 0 || whole + fraction > 15 ||
        length > 15 || !((blank >> length) & 1)) {
      shape.known = false;
      return false;
    }
    shape.whole = static_cast<uint8_t>(whole);
    shape.fraction = static_cast<uint8_t>(fraction);
    shape.length = static_cast<uint8_t>(length);
    shape.window = (2u << length) - 1;
    shape.digits = ((1u << whole) - 1) | (((1u << fraction) - 1) << (whole + 1));
    shape.dot = has_dot ? 1u << whole : 0;
    shape.known = true;
  }
  uint64_t mantissa = 0;
  if (shape.whole) {
    uint64_t chunk;
    std::memcpy(&chunk, q, 8);
    mantissa = eight_digits_value(chunk, shape.whole);
  }
  if (shape.fraction) {
    uint64_t chunk;
    std::memcpy(&chunk, q + shape.whole + 1, 8);
    mantissa = mantissa * kPowers[shape.fraction] + eight_digits_value(chunk, shape.fraction);
  }
  const double magnitude = static_cast<double>(mantissa) / kPowersOfTen[shape.fraction];
  value = negative ? -magnitude : magnitude;
  after = q + shape.length;
  return true;
#else
  (void)first, (void)end, (void)shape, (void)value, (void)after;
  return false;
#endif
}

/// parse_shaped's counterpart for an index of 1 to 8 digits, its column's last length in
/// `length` (0: none yet): the digit run at `first` read from one 16-byte mask and one 8-byte
/// load when its length is the expected one, else measured on the mask. Returns the run's end
/// (a non-digit, not looked at further) with its value in `value`, or nullptr, with nothing
/// changed but `length`, when the run is empty or longer than 8 digits or fewer than 16 bytes
/// are left; then parse_integer decides. The value is parse_integer's.
inline const char* parse_shaped_index(const char* first, const char* end, uint8_t& length,
                                      uint64_t& value) {
#if defined(__SSE2__)
  if (end - first < 16) return nullptr;
  const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first));
  const __m128i less_zero = _mm_sub_epi8(bytes, _mm_set1_epi8('0'));
  const auto digit = static_cast<uint32_t>(
      _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_min_epu8(less_zero, _mm_set1_epi8(9)), less_zero)));
  // The expected length's digits and a non-digit after them.
  if (length == 0 || (digit & ((2u << length) - 1)) != (1u << length) - 1) {
    const int run = __builtin_ctz(~digit);
    if (run == 0 || run > 8) {
      length = 0;
      return nullptr;
    }
    length = static_cast<uint8_t>(run);
  }
  uint64_t chunk;
  std::memcpy(&chunk, first, 8);
  value = eight_digits_value(chunk, length);
  return first + length;
#else
  (void)first, (void)end, (void)length, (void)value;
  return nullptr;
#endif
}

/// `text` with every byte that is not printable ASCII (a control byte, DEL, 0x80 and above)
/// written as \xNN, so that a message quoting a file's bytes is neither cut short at a NUL nor
/// sends a terminal escape sequences.
inline std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f) {
      out += c;
    } else {
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 15];
    }
  }
  return out;
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
  s += printable(std::string_view(p, static_cast<size_t>(q - p)));
  if (q < end && !is_blank_or_eol(*q)) s += "...";
  s += '\'';
  return s;
}

}  // namespace snag::io::detail
