// The text readers' number parsing (lib/src/io/text_scan.h): parse_double's fast path must give
// exactly what fast_float gives, value, bits and where the number ends, and accept and reject
// exactly the same tokens; glibc's strtod (correctly rounded) is the independent reference for
// the values. parse_integer's digit loop must give what std::from_chars gives.
#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>

#include "../../lib/src/io/text_scan.h"

namespace {

using snag::io::detail::parse_double;

/// parse_double against fast_float (and the value against strtod) on the start of `text`.
void expect_as_fast_float(const std::string& text) {
  const char* first = text.data();
  const char* end = text.data() + text.size();
  double ours = -7.0, theirs = -7.0;
  const auto a = parse_double(first, end, ours);
  const auto b = fast_float::from_chars(first, end, theirs);
  ASSERT_EQ(a.ec, b.ec) << "'" << text << "'";
  ASSERT_EQ(a.ptr, b.ptr) << "'" << text << "'";
  if (b.ec != std::errc()) return;
  ASSERT_EQ(std::bit_cast<uint64_t>(ours), std::bit_cast<uint64_t>(theirs)) << "'" << text << "'";
  // glibc's strtod rounds correctly; the token is what fast_float consumed.
  const std::string token(first, b.ptr);
  ASSERT_EQ(std::bit_cast<uint64_t>(ours),
            std::bit_cast<uint64_t>(std::strtod(token.c_str(), nullptr)))
      << "'" << token << "'";
}

/// A random plain decimal: '-' two times in five, 0 to `most_whole` integer digits, and four
/// times in five a point with 0 to `most_fraction` digits after it; `whole` and `fraction`
/// receive the digit counts.
std::string random_decimal(std::mt19937& rng, int most_whole, int most_fraction, int& whole,
                           int& fraction) {
  std::uniform_int_distribution<int> digit(0, 9), integer_digits(0, most_whole),
      fraction_digits(0, most_fraction), pick(0, 4);
  std::string token;
  if (pick(rng) < 2) token += '-';
  whole = integer_digits(rng);
  for (int d = 0; d < whole; ++d) token += static_cast<char>('0' + digit(rng));
  const bool point = pick(rng) > 0;
  fraction = point ? fraction_digits(rng) : 0;
  if (point) token += '.';
  for (int d = 0; d < fraction; ++d) token += static_cast<char>('0' + digit(rng));
  return token;
}

TEST(TextScan, CoordinatesParseAsFastFloatAndStrtodWhateverTheirDigits) {
  std::mt19937 rng(20261124);
  std::uniform_int_distribution<int> pick(0, 4);
  const char* const ends[] = {" ", "\n", "\r\n", "", "\t1"};
  int fast = 0;
  for (int i = 0; i < 200000; ++i) {
    int whole, fraction;
    const std::string token = random_decimal(rng, 17, 25, whole, fraction);
    fast += whole + fraction >= 1 && whole + fraction <= 15;
    expect_as_fast_float(token + ends[pick(rng)]);
  }
  EXPECT_GT(fast, 50000);  // the fast path was taken often
}

/// Random text after a token: digits, points, signs, blanks, letters, the bytes on either side
/// of the digits ('/' and ':'), NUL, DEL and bytes with the top bit set, so that whatever a
/// parser reads past the token, or stops at, is there.
std::string random_tail(std::mt19937& rng) {
  static const char kBytes[] = "059.-+ \n\rex/:\x7f\x80\xfa\xff";  // and the terminating NUL
  std::uniform_int_distribution<int> length(0, 24), pick(0, sizeof kBytes - 1);
  std::string tail(static_cast<size_t>(length(rng)), ' ');
  for (char& c : tail) c = kBytes[pick(rng)];
  return tail;
}

// Tokens inside a text, as in a file: what follows a number is any text, not the text's end.
// Two tokens in five are followed by the random text directly, so that the characters right after
// the digits are any of those bytes; the others by a blank or a line end first.
TEST(TextScan, CoordinatesFollowedByAnyTextParseAsFastFloat) {
  std::mt19937 rng(20261202);
  std::uniform_int_distribution<int> pick(0, 4);
  const char* const ends[] = {" ", "\n", "\r\n", "", "\t1"};
  for (int i = 0; i < 300000; ++i) {
    int whole, fraction;
    const std::string token = random_decimal(rng, 9, 9, whole, fraction);
    const bool direct = pick(rng) < 2;
    expect_as_fast_float(token + (direct ? "" : ends[pick(rng)]) + random_tail(rng));
  }
}

/// parse_integer against std::from_chars: the value, where it ends and whether it failed.
void expect_as_from_chars(const std::string& text) {
  const char* first = text.data();
  const char* end = text.data() + text.size();
  int64_t ours = -7, theirs = -7;
  const auto a = snag::io::detail::parse_integer(first, end, ours);
  const auto b = std::from_chars(first, end, theirs);
  ASSERT_EQ(a.ec, b.ec) << "'" << text << "'";
  ASSERT_EQ(a.ptr, b.ptr) << "'" << text << "'";
  if (b.ec == std::errc()) ASSERT_EQ(ours, theirs) << "'" << text << "'";
}

TEST(TextScan, IndicesParseAsFromChars) {
  std::mt19937 rng(1202);
  std::uniform_int_distribution<int> digit(0, 9), digits(0, 21), pick(0, 3);
  for (int i = 0; i < 300000; ++i) {
    std::string token;
    if (pick(rng) == 0) token += '-';
    const int count = digits(rng);
    for (int d = 0; d < count; ++d) token += static_cast<char>('0' + digit(rng));
    expect_as_from_chars(token + random_tail(rng));
  }
  for (const char* text :
       {"0", "7 ", "12345678", "1234567 ", "12345678 1", "99999999999999999999",
        "9223372036854775807 ", "9223372036854775808        ", "-1 2 3 4 5 6", "00000001/2/3"})
    expect_as_from_chars(text);
}

TEST(TextScan, TokensThatAreNotPlainDecimalsGoToFastFloat) {
  for (const char* token :
       {"-",
        ".",
        "-.",
        ".5",
        "-.5",
        "1.",
        "-0.000000",
        "0.000000",
        "1.5x",
        "1.2.3",
        "1e5",
        "-2.5E-3",
        "0x10",
        "nan",
        "-inf",
        "infinity",
        "+1",
        "--1",
        "123456789012345",
        "1234567890123456",
        "0.123456789012345",
        "0.1234567890123456",
        "000000000000000001.5",
        "1,5",
        "9007199254740993",
        "179769313486231570000000000000000000000000000000000000000000000000000000000000000000000"
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000"}) {
    for (const char* end : {"", " ", "\n", "x"}) {
      SCOPED_TRACE(std::string(token) + end);
      expect_as_fast_float(std::string(token) + end);
    }
  }
  double zero = 1.0;
  const std::string negative_zero = "-0.000000";
  parse_double(negative_zero.data(), negative_zero.data() + negative_zero.size(), zero);
  EXPECT_TRUE(std::signbit(zero));
}

}  // namespace
