// The tags.layout format (core/sfm/tag_layout.h): its writer and reader round trip, both line forms,
// and errors that name the file and line.
#include "core/sfm/tag_layout.h"

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace reconar {
namespace {

// The writer (tag registration's tags.layout) and the reader are one module: what is written reads
// back to the same tags, and writing that again gives the same bytes.
TEST(TagLayoutTest, FormatReadsBackExactly) {
  std::vector<LayoutTag> tags(2);
  tags[0].id = 2;
  tags[0].size = 0.127;
  tags[0].layout_from_tag.translation = Eigen::Vector3d(0.1, -1.0 / 3.0, 2.5);
  tags[0].layout_from_tag.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  tags[1].id = 9;
  tags[1].size = 0.127;
  const std::string text = FormatTagLayout(tags);
  EXPECT_EQ(text.rfind("# reconar tag layout: id size x y z qw qx qy qz (world_from_tag, metres)\n2 0.127 ", 0), 0u)
      << text;
  const Result<TagLayout> layout = ParseTagLayout(text, "tags.layout");
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  ASSERT_EQ(layout->tags().size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(layout->tags()[i].id, tags[i].id);
    EXPECT_EQ(layout->tags()[i].size, tags[i].size);
    EXPECT_EQ(layout->tags()[i].layout_from_tag.translation, tags[i].layout_from_tag.translation);
    EXPECT_LT((layout->tags()[i].layout_from_tag.rotation - tags[i].layout_from_tag.rotation).norm(), 1e-15);
  }
  // The rotation is stored as a quaternion: a second round trip may move its last digit (FMA on
  // aarch64), so it is compared as a rotation, not as text.
  const Result<TagLayout> again = ParseTagLayout(FormatTagLayout(layout->tags()), "again");
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(again->tags()[i].layout_from_tag.translation, tags[i].layout_from_tag.translation);
    EXPECT_LT((again->tags()[i].layout_from_tag.rotation - tags[i].layout_from_tag.rotation).norm(), 1e-15);
  }
}

TEST(TagLayoutTest, ParsesBothLineFormsAndComments) {
  const Result<TagLayout> layout = ParseTagLayout(
      "# a board\n"
      "3 0.05 0.1 0.2            # planar, no angle\n"
      "\n"
      "1 0.04 -0.1 0.0 90\n"
      "7 0.06 0 0 0.5 0.7071067811865476 0.7071067811865476 0 0\n",
      "board.txt");
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  ASSERT_EQ(layout->tags().size(), 3u);
  EXPECT_EQ(layout->tags()[0].id, 1);  // sorted by id
  const LayoutTag* one = layout->Find(1);
  ASSERT_NE(one, nullptr);
  EXPECT_DOUBLE_EQ(one->size, 0.04);
  EXPECT_LT((one->layout_from_tag * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(-0.1, 1.0, 0.0)).norm(), 1e-12);
  const LayoutTag* seven = layout->Find(7);
  ASSERT_NE(seven, nullptr);
  EXPECT_LT((seven->layout_from_tag.rotation * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_EQ(layout->Find(2), nullptr);
  EXPECT_FALSE(layout->IsPlanar());
  EXPECT_TRUE(ParseTagLayout("1 0.1 0 0\n2 0.1 0.2 0 45\n", "x").value().IsPlanar());
}

TEST(TagLayoutTest, ErrorsNameTheFileAndLine) {
  const auto message = [](const std::string& text) {
    const Result<TagLayout> layout = ParseTagLayout(text, "board.txt");
    EXPECT_FALSE(layout.ok()) << text;
    return layout.ok() ? std::string() : layout.status().message();
  };
  EXPECT_NE(message("1 0.1 0 0\n2 0.1 zero 0\n").find("board.txt:2"), std::string::npos);
  EXPECT_NE(message("1 0.1 0 0 0 0\n").find("6 fields"), std::string::npos);
  EXPECT_NE(message("1 0.1 0 0\n1 0.2 1 1\n").find("twice"), std::string::npos);
  EXPECT_NE(message("1 -0.1 0 0\n").find("size"), std::string::npos);
  EXPECT_NE(message("1.5 0.1 0 0\n").find("integer"), std::string::npos);
  EXPECT_NE(message("1 0.1 0 0 0 0 0 0 0\n").find("quaternion"), std::string::npos);
  EXPECT_NE(message("# nothing\n").find("no tags"), std::string::npos);
  const Result<TagLayout> missing = ReadTagLayout("/nonexistent/board.txt");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace reconar
