#include "core/base/binary_io.h"

#include <gtest/gtest.h>

#include <string>

namespace reconar {
namespace {

TEST(Crc32, MatchesTheStandardCheckValue) {
  // The CRC-32 catalogue's check value: crc32("123456789") = 0xCBF43926.
  EXPECT_EQ(Crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(Crc32("", 0), 0u);
  // Continuing over two parts equals one pass.
  EXPECT_EQ(Crc32("6789", 4, Crc32("12345", 5)), 0xCBF43926u);
}

TEST(ByteReader, ReadsWhatTheWriterWrote) {
  ByteWriter writer;
  writer.Put<uint32_t>(7);
  writer.Put<double>(-2.5);
  writer.PutString("map");
  ByteReader reader(writer.bytes());
  uint32_t u = 0;
  double d = 0;
  std::string s;
  ASSERT_TRUE(reader.Get(&u) && reader.Get(&d) && reader.GetString(16, &s));
  EXPECT_EQ(u, 7u);
  EXPECT_EQ(d, -2.5);
  EXPECT_EQ(s, "map");
  EXPECT_EQ(reader.remaining(), 0u);
}

TEST(ByteReader, RefusesToReadPastTheEndAndStaysFailed) {
  ByteWriter writer;
  writer.Put<uint16_t>(1);
  ByteReader reader(writer.bytes());
  uint32_t u = 99;
  EXPECT_FALSE(reader.Get(&u));
  EXPECT_EQ(u, 99u);
  EXPECT_FALSE(reader.ok());
  uint8_t b = 0;
  EXPECT_FALSE(reader.Get(&b));  // failed readers stay failed even when a byte is left
}

TEST(ByteReader, RefusesACountTheBytesCannotHold) {
  ByteWriter writer;
  writer.Put<uint32_t>(1000);  // claims 1000 doubles
  writer.Put<double>(1.0);
  ByteReader reader(writer.bytes());
  uint32_t n = 0;
  EXPECT_FALSE(reader.GetCount(sizeof(double), 1u << 30, &n));
  ByteReader capped(writer.bytes());
  EXPECT_FALSE(capped.GetCount(0, 10, &n));  // above max_count
  ByteWriter ok_writer;
  ok_writer.Put<uint32_t>(1);
  ok_writer.Put<double>(1.0);
  ByteReader ok(ok_writer.bytes());
  EXPECT_TRUE(ok.GetCount(sizeof(double), 10, &n));
  EXPECT_EQ(n, 1u);
}

}  // namespace
}  // namespace reconar
