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

/// parse_shaped on the start of `text`, with the column's `shape` carried from the call before:
/// when it reads the token, the value's bits and the token's end must be parse_double's (which
/// the tests above hold to fast_float's and strtod's), and a blank or a line end must follow.
/// Returns whether it read the token.
bool expect_shaped_as_parse_double(const std::string& text, snag::io::detail::DecimalShape& shape) {
  const char* first = text.data();
  const char* end = text.data() + text.size();
  double ours = -7.0, theirs = -7.0;
  const char* after = nullptr;
  if (!snag::io::detail::parse_shaped(first, end, shape, ours, after)) return false;
  const auto b = parse_double(first, end, theirs);
  EXPECT_EQ(b.ec, std::errc()) << "'" << text << "'";
  EXPECT_EQ(after, b.ptr) << "'" << text << "'";
  EXPECT_EQ(std::bit_cast<uint64_t>(ours), std::bit_cast<uint64_t>(theirs)) << "'" << text << "'";
  EXPECT_TRUE(after < end && snag::io::detail::is_blank_or_eol(*after)) << "'" << text << "'";
  return true;
}

// A column of coordinates as a writer prints it: one layout most of the time (the shape
// parse_shaped expects), now and then another, and now and then the token spoiled by one byte
// (a digit made another byte; a digit added; the blank after it made another byte), each followed
// by a blank or line end and any text. Every token parse_shaped takes must be parse_double's, and
// the unspoiled tokens of the usual layout must be taken.
TEST(TextScan, ShapedCoordinatesParseAsParseDouble) {
  std::mt19937 rng(20261202);
  std::uniform_int_distribution<int> pick(0, 99), digit(0, 9), layout_digits(0, 9);
  // Around each class's edges: digits ('/' ':'), blanks ('\b' '\x0e' on either side of '\t' to
  // '\r'), and NUL, DEL, bytes above 0x7f.
  static const char kSpoilers[] = "0.e/:-+ \b\x0e\x01\x7f\x80\xff";  // and NUL
  std::uniform_int_distribution<int> spoiler(0, sizeof kSpoilers - 1);
  const char* const ends[] = {" ", "\n", "\r\n", "\t", "\v", "\f"};
  std::uniform_int_distribution<int> pick_end(0, 5);
  for (int column = 0; column < 200; ++column) {
    snag::io::detail::DecimalShape shape;
    int whole = layout_digits(rng), fraction = layout_digits(rng);
    bool point = pick(rng) < 80;
    int usual = 0, usual_taken = 0, taken = 0;
    for (int i = 0; i < 2000; ++i) {
      const int roll = pick(rng);
      if (roll < 3) {  // the writer's layout changes
        whole = layout_digits(rng);
        fraction = layout_digits(rng);
        point = pick(rng) < 80;
      }
      std::string token = pick(rng) < 40 ? "-" : "";
      for (int d = 0; d < whole; ++d) token += static_cast<char>('0' + digit(rng));
      if (point) token += '.';
      for (int d = 0; d < (point ? fraction : 0); ++d) token += static_cast<char>('0' + digit(rng));
      std::string after = ends[pick_end(rng)];
      const bool spoiled = roll >= 3 && roll < 13;
      if (spoiled) {
        const int how = pick(rng) % 3;
        if (how == 0 && !token.empty())
          token[static_cast<size_t>(pick(rng)) % token.size()] = kSpoilers[spoiler(rng)];
        else if (how == 1)
          token += static_cast<char>('0' + digit(rng));
        else
          after = std::string(1, kSpoilers[spoiler(rng)]);
      }
      const std::string text = token + after + random_tail(rng) + std::string(24, 'x');
      const bool took = expect_shaped_as_parse_double(text, shape);
      if (::testing::Test::HasFailure()) return;
      taken += took;
      // The usual layout, unspoiled and in the fast path's reach, after one token to learn it.
      const int length = whole + (point ? 1 + fraction : 0);
      if (!spoiled && roll >= 13 && i > 0 && whole + (point ? fraction : 0) > 0 && whole <= 8 &&
          (point ? fraction : 0) <= 8 && length <= 15) {
        ++usual;
        usual_taken += took;
      }
    }
    EXPECT_GE(usual_taken, usual * 9 / 10) << "column " << column;
    EXPECT_GT(taken, 0);
  }
}

TEST(TextScan, ShapedCoordinatesLeaveShortTextsAndOtherTokensToParseDouble) {
  snag::io::detail::DecimalShape shape;
  double value = 0;
  const char* after = nullptr;
  const std::string pad(24, ' ');
  // Too close to the end of the text: not read, whatever the shape.
  const std::string short_text = "1.5 2.5 3.5";
  EXPECT_FALSE(snag::io::detail::parse_shaped(
      short_text.data(), short_text.data() + short_text.size(), shape, value, after));
  for (const char* token : {"1e5", "+1.5", "--1", "1.2.3", ".", "-", "123456789.5", "1.123456789",
                            "0x10", "nan", "1,5", "5/6"}) {
    const std::string text = token + pad;
    // With the shape of "1.5" known, and with none.
    for (const char* learned : {"1.5", ""}) {
      shape = {};
      if (*learned) {
        const std::string first = learned + pad;
        ASSERT_TRUE(snag::io::detail::parse_shaped(first.data(), first.data() + first.size(), shape,
                                                   value, after));
      }
      EXPECT_FALSE(snag::io::detail::parse_shaped(text.data(), text.data() + text.size(), shape,
                                                  value, after))
          << token;
    }
  }
  double zero = 1.0;
  shape = {};
  const std::string negative_zero = "-0.000000" + pad;
  ASSERT_TRUE(snag::io::detail::parse_shaped(
      negative_zero.data(), negative_zero.data() + negative_zero.size(), shape, zero, after));
  EXPECT_TRUE(std::signbit(zero));
  EXPECT_EQ(zero, 0.0);
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

// A column of indices: one length most of the time, now and then another (1 to 10 digits, so
// that some are past the 8 parse_shaped_index reads), and now and then one spoiled by a byte
// (a digit made another byte, or the byte after the run made a digit). Each run it reads must be
// parse_integer's, value and end; the unspoiled runs of up to 8 digits must all be read.
TEST(TextScan, ShapedIndicesParseAsParseInteger) {
  std::mt19937 rng(1203);
  std::uniform_int_distribution<int> pick(0, 99), digit(0, 9), run_length(1, 10);
  static const char kSpoilers[] = "0/:- \n\x01\x7f\x80\xff";  // and NUL
  std::uniform_int_distribution<int> spoiler(0, sizeof kSpoilers - 1);
  for (int column = 0; column < 200; ++column) {
    uint8_t length = 0;
    int digits = run_length(rng), plain = 0, plain_taken = 0;
    for (int i = 0; i < 2000; ++i) {
      const int roll = pick(rng);
      if (roll < 3) digits = run_length(rng);
      std::string token;
      for (int d = 0; d < digits; ++d) token += static_cast<char>('0' + digit(rng));
      std::string after = pick(rng) < 50 ? " " : "\n";
      const bool spoiled = roll >= 3 && roll < 13;
      if (spoiled) {
        if (pick(rng) < 50)
          token[static_cast<size_t>(pick(rng)) % token.size()] = kSpoilers[spoiler(rng)];
        else
          after = std::string(1, static_cast<char>('0' + digit(rng)));
      }
      const std::string text = token + after + random_tail(rng) + std::string(16, 'x');
      const char* first = text.data();
      const char* end = first + text.size();
      uint64_t ours = 0;
      const char* read = snag::io::detail::parse_shaped_index(first, end, length, ours);
      if (read) {
        int64_t theirs = -1;
        const auto b = snag::io::detail::parse_integer(first, end, theirs);
        ASSERT_EQ(b.ec, std::errc()) << "'" << text << "'";
        ASSERT_EQ(read, b.ptr) << "'" << text << "'";
        ASSERT_EQ(static_cast<int64_t>(ours), theirs) << "'" << text << "'";
      }
      if (!spoiled && digits <= 8) {
        ++plain;
        plain_taken += read != nullptr;
      }
    }
    EXPECT_EQ(plain_taken, plain) << "column " << column;
  }
  uint8_t length = 0;
  uint64_t value = 0;
  const std::string short_text = "12 13 14";
  EXPECT_EQ(snag::io::detail::parse_shaped_index(
                short_text.data(), short_text.data() + short_text.size(), length, value),
            nullptr);
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
