// The text readers' number parsing (lib/src/io/text_scan.h): parse_double's fast path must give
// exactly what fast_float gives, value, bits and where the number ends, and accept and reject
// exactly the same tokens; glibc's strtod (correctly rounded) is the independent reference for
// the values.
#include <gtest/gtest.h>

#include <bit>
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

TEST(TextScan, CoordinatesParseAsFastFloatAndStrtodWhateverTheirDigits) {
  std::mt19937 rng(20261124);
  std::uniform_int_distribution<int> digit(0, 9), integer_digits(0, 17), fraction_digits(0, 25),
      pick(0, 4);
  const char* const ends[] = {" ", "\n", "\r\n", "", "\t1"};
  int fast = 0;
  for (int i = 0; i < 200000; ++i) {
    std::string token;
    if (pick(rng) < 2) token += '-';
    const int whole = integer_digits(rng);
    for (int d = 0; d < whole; ++d) token += static_cast<char>('0' + digit(rng));
    const bool point = pick(rng) > 0;
    const int fraction = point ? fraction_digits(rng) : 0;
    if (point) token += '.';
    for (int d = 0; d < fraction; ++d) token += static_cast<char>('0' + digit(rng));
    fast += whole + fraction >= 1 && whole + fraction <= 15;
    expect_as_fast_float(token + ends[pick(rng)]);
  }
  EXPECT_GT(fast, 50000);  // the fast path was taken often
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
