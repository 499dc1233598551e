// The one shortest-round-trip formatter writes exactly what the four formatters it replaced wrote
// (std::to_chars of the double or float: JsonWriter, COLMAP model text, calibration files, mesh
// text formats), so that every file keeps its bytes.
#include "core/base/number_format.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include "core/base/json_writer.h"

namespace reconar {
namespace {

template <typename T>
std::string ToChars(T value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

TEST(NumberFormat, EdgeValuesOfDoubles) {
  EXPECT_EQ(FormatShortest(0.0), "0");
  EXPECT_EQ(FormatShortest(-0.0), "-0");
  EXPECT_EQ(FormatShortest(1.0), "1");
  EXPECT_EQ(FormatShortest(-42.0), "-42");
  EXPECT_EQ(FormatShortest(123456.0), "123456");
  EXPECT_EQ(FormatShortest(1e6), "1e+06");  // the shorter of the fixed and scientific forms
  EXPECT_EQ(FormatShortest(1e21), "1e+21");
  EXPECT_EQ(FormatShortest(0.1), "0.1");
  EXPECT_EQ(FormatShortest(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(FormatShortest(1e-300), "1e-300");
  EXPECT_EQ(FormatShortest(std::numeric_limits<double>::denorm_min()), "5e-324");
  EXPECT_EQ(FormatShortest(-std::numeric_limits<double>::min()), "-2.2250738585072014e-308");
  EXPECT_EQ(FormatShortest(std::numeric_limits<double>::max()), "1.7976931348623157e+308");
  EXPECT_EQ(FormatShortest(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatShortest(-std::numeric_limits<double>::infinity()), "-inf");
  EXPECT_EQ(FormatShortest(std::numeric_limits<double>::quiet_NaN()),
            ToChars(std::numeric_limits<double>::quiet_NaN()));
}

TEST(NumberFormat, FloatsKeepFloatPrecision) {
  EXPECT_EQ(FormatShortest(0.1f), "0.1");
  EXPECT_EQ(FormatShortest(static_cast<double>(0.1f)), "0.10000000149011612");
  EXPECT_EQ(FormatShortest(-0.0f), "-0");
  EXPECT_EQ(FormatShortest(16777216.0f), "16777216");
  EXPECT_EQ(FormatShortest(std::numeric_limits<float>::denorm_min()), "1e-45");
  EXPECT_EQ(FormatShortest(1.0f / 3.0f), "0.33333334");
}

TEST(NumberFormat, AppendsAndMatchesToCharsOnRandomValues) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  for (int i = 0; i < 20000; ++i) {
    const double value = std::ldexp(mantissa(rng), exponent(rng) / 4);
    std::string text = "x=";
    AppendShortest(&text, value);
    ASSERT_EQ(text, "x=" + ToChars(value));
    EXPECT_EQ(std::strtod(text.c_str() + 2, nullptr), value);  // round trip
    const float single = static_cast<float>(value);
    ASSERT_EQ(FormatShortest(single), ToChars(single));
    EXPECT_EQ(std::strtof(FormatShortest(single).c_str(), nullptr), single);
  }
}

TEST(NumberFormat, JsonWriterWritesNumbersThroughIt) {
  JsonWriter json;
  json.BeginArray().Double(0.1).Double(-0.0).Double(1e-300).Double(std::nan("")).Double(3.0).EndArray();
  EXPECT_EQ(json.str(), "[0.1,-0,1e-300,null,3]");
}

}  // namespace
}  // namespace reconar
