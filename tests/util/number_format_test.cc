#include "rcm/util/number_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "rcm/util/message_text.h"

namespace rcm::number_format_test {
namespace {

struct Case {
  double value;
  const char* python_repr;
};

// Expected strings are the output of Python 3's repr() on the same literal.
TEST(FormatDouble, MatchesPythonRepr) {
  const Case kCases[] = {
      {0.1, "0.1"},
      {0.3, "0.3"},
      {0.5, "0.5"},
      {1.0, "1.0"},
      {-1.5, "-1.5"},
      {100.0, "100.0"},
      {0.0, "0.0"},
      {-0.0, "-0.0"},
      {1e-05, "1e-05"},
      {3e-05, "3e-05"},
      {1.2345e-05, "1.2345e-05"},
      {0.0001, "0.0001"},
      {0.00012345, "0.00012345"},
      {123456789012345678.0, "1.2345678901234568e+17"},
      {12345678901234567890.0, "1.2345678901234567e+19"},
      {1e15, "1000000000000000.0"},
      {1234567890123456.7, "1234567890123456.8"},
      {1e16, "1e+16"},
      {9999999999999998.0, "9999999999999998.0"},
      {1e100, "1e+100"},
      {5e-324, "5e-324"},
      {-1e-300, "-1e-300"},
      {2.2250738585072014e-308, "2.2250738585072014e-308"},
      {1.7976931348623157e308, "1.7976931348623157e+308"},
      {346.68681661781403, "346.68681661781403"},
      {2.365797666527927e-05, "2.365797666527927e-05"},
      {-0.037934508908317364, "-0.037934508908317364"},
  };
  for (const Case& c : kCases) {
    EXPECT_EQ(FormatDouble(c.value), c.python_repr);
  }
}

TEST(FormatDouble, NonFiniteValuesUsePythonSpelling) {
  EXPECT_EQ(FormatDouble(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(FormatDouble(-std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(FormatDouble(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatDouble(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(FormatDouble, RandomBitPatternsRoundTripExactly) {
  std::mt19937_64 random(20240611);
  int checked = 0;
  while (checked < 100000) {
    const uint64_t bits = random();
    double value;
    std::memcpy(&value, &bits, sizeof(value));
    if (!std::isfinite(value)) continue;
    const std::string text = FormatDouble(value);
    const double parsed = std::strtod(text.c_str(), nullptr);
    uint64_t parsed_bits;
    std::memcpy(&parsed_bits, &parsed, sizeof(parsed));
    ASSERT_EQ(parsed_bits, bits) << text;
    ++checked;
  }
}

// QuoteForMessage (rcm/util/message_text.h) quotes the values that every
// reader's error messages show; the readers' tests check it in context.

TEST(QuoteForMessage, QuotesTextAsItIs) {
  EXPECT_EQ(QuoteForMessage("6cm"), "'6cm'");
  EXPECT_EQ(QuoteForMessage(""), "''");
  EXPECT_EQ(QuoteForMessage("it's 3.5 \xC2\xB5m"), "'it's 3.5 \xC2\xB5m'");
}

TEST(QuoteForMessage, ShowsControlCharactersAsHexEscapes) {
  EXPECT_EQ(QuoteForMessage("pin\nhole"), "'pin\\x0ahole'");
  EXPECT_EQ(QuoteForMessage(std::string("a\tb\r\0c\x7f", 7)),
            "'a\\x09b\\x0d\\x00c\\x7f'");
  EXPECT_EQ(EscapeForMessage("1\x1f"), "1\\x1f");
}

TEST(QuoteForMessage, ShortensTextPast40Bytes) {
  const std::string forty(40, 'x');
  EXPECT_EQ(QuoteForMessage(forty), "'" + forty + "'");
  EXPECT_EQ(QuoteForMessage(forty + "yz"), "'" + forty + "...'");
  // The limit counts the bytes of the text, not of its escapes.
  EXPECT_EQ(QuoteForMessage(std::string(39, 'x') + "\n\n"),
            "'" + std::string(39, 'x') + "\\x0a...'");
}

TEST(EscapeControlCharacters, EscapesWithoutShortening) {
  const std::string long_text(50, 'x');
  EXPECT_EQ(EscapeControlCharacters(long_text + "\n"), long_text + "\\x0a");
  EXPECT_EQ(EscapeControlCharacters("unknown escape character: \x01"),
            "unknown escape character: \\x01");
}

TEST(FormatFixed, PrintsFixedDecimalsAndNaForNonFinite) {
  EXPECT_EQ(FormatFixed(1.334981, 5), "1.33498");
  EXPECT_EQ(FormatFixed(0.5, 0), "0");
  EXPECT_EQ(FormatFixed(-2.0, 2), "-2.00");
  EXPECT_EQ(FormatFixed(NAN, 3), "n/a");
  EXPECT_EQ(FormatFixed(-INFINITY, 3), "n/a");
}

}  // namespace
}  // namespace rcm::number_format_test
