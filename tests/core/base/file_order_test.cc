#include "core/base/file_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace reconar {
namespace {

TEST(FileOrder, NumbersCompareByValue) {
  std::vector<std::string> names = {"frame_10.png", "frame_2.png", "frame_1.png", "frame_100.png", "frame_9.png"};
  SortFileNames(&names);
  EXPECT_EQ(names,
            (std::vector<std::string>{"frame_1.png", "frame_2.png", "frame_9.png", "frame_10.png", "frame_100.png"}));
}

TEST(FileOrder, ZeroPaddedNamesKeepTheirStringOrder) {
  std::vector<std::string> names;
  for (int i = 0; i < 1200; i += 7) {
    char name[32];
    std::snprintf(name, sizeof(name), "IMG_%04d.JPG", i);
    names.push_back(name);
  }
  std::vector<std::string> natural = names;
  std::shuffle(natural.begin(), natural.end(), std::mt19937(3));
  SortFileNames(&natural);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(natural, names);
}

TEST(FileOrder, TextAndTiesAreTotal) {
  EXPECT_TRUE(FileNameLess("a.png", "b.png"));
  EXPECT_FALSE(FileNameLess("b.png", "a.png"));
  EXPECT_TRUE(FileNameLess("a", "a1"));
  EXPECT_TRUE(FileNameLess("a2b", "a10"));
  EXPECT_TRUE(FileNameLess("x9y2", "x9y10"));
  EXPECT_TRUE(FileNameLess("100_7100.JPG", "100_7101.JPG"));
  // Equal in value: the byte order decides, and never both ways.
  EXPECT_TRUE(FileNameLess("frame_01.png", "frame_1.png"));
  EXPECT_FALSE(FileNameLess("frame_1.png", "frame_01.png"));
  EXPECT_FALSE(FileNameLess("same.png", "same.png"));
  // Numbers longer than any integer type still compare by value.
  EXPECT_TRUE(FileNameLess("n99999999999999999999999", "n100000000000000000000000"));
}

TEST(FileOrder, IsAStrictWeakOrderOnMixedNames) {
  std::vector<std::string> names = {"a", "a0", "a00", "a1", "a01", "a10", "a1b", "a1a",  "a_2",  "b",
                                    "B", "1",  "01",  "10", "9x",  "",    "a9",  "a9.9", "a9.10"};
  for (const std::string& a : names) {
    EXPECT_FALSE(FileNameLess(a, a)) << a;
    for (const std::string& b : names) {
      if (a != b) {
        EXPECT_NE(FileNameLess(a, b), FileNameLess(b, a)) << a << " " << b;
      }
      for (const std::string& c : names) {
        if (FileNameLess(a, b) && FileNameLess(b, c)) {
          EXPECT_TRUE(FileNameLess(a, c)) << a << " " << b << " " << c;
        }
      }
    }
  }
}

}  // namespace
}  // namespace reconar
