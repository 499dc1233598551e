#include "tests/support/localize_json.h"

#include <gtest/gtest.h>

namespace reconar {
namespace {

constexpr char kRegistered[] =
    R"({"image": "a.png", "registered": true, "cam_from_world": {"R": [1, 0, 0, 0, 1, 0, 0, 0, 1], )"
    R"("t": [1, 2, 3]}, "camera": {"width": 640, "height": 480, "fx": 500, "fy": 510, "cx": 320, "cy": 240, )"
    R"("k1": 0.1, "k2": -0.01, "source": "exif"}, "inliers": 55, "matches": 80, "features": 900, "ms": 12.5, )"
    R"("reason": ""})";
constexpr char kUnregistered[] =
    R"({"image": "b.png", "registered": false, "inliers": 3, "matches": 9, "features": 700, "ms": 4, )"
    R"("reason": "too few 2D-3D matches"})";

TEST(LocalizeJson, ReadsRegisteredAndUnregisteredLines) {
  auto parsed = testing::ParseLocalizeJson(std::string("progress line\n") + kRegistered + "\n" + kUnregistered + "\n");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  ASSERT_EQ(parsed->size(), 2u);
  const testing::LocalizedPhoto& a = parsed->at("a.png");
  EXPECT_TRUE(a.registered);
  EXPECT_EQ(a.inliers, 55);
  EXPECT_DOUBLE_EQ(a.ms, 12.5);
  EXPECT_TRUE(a.Centre().isApprox(Eigen::Vector3d(-1, -2, -3)));
  EXPECT_DOUBLE_EQ(a.camera.focal, 500.0);
  EXPECT_DOUBLE_EQ(a.camera.fy(), 510.0);
  EXPECT_DOUBLE_EQ(a.camera.k2, -0.01);
  const testing::LocalizedPhoto& b = parsed->at("b.png");
  EXPECT_FALSE(b.registered);
  EXPECT_EQ(b.reason, "too few 2D-3D matches");
}

TEST(LocalizeJson, RefusesBrokenLines) {
  for (const std::string& line :
       {std::string("{\"image\": \"a.png\""), std::string("{\"registered\": false}"),
        std::string(R"({"image": "a.png", "registered": true, "inliers": 1, "ms": 1, "reason": ""})"),
        std::string(R"({"image": "a.png", "registered": "yes", "inliers": 1, "ms": 1, "reason": ""})"),
        std::string(kRegistered).replace(std::string(kRegistered).find("[1, 2, 3]"), 9, "[1, 2]"),
        std::string(kRegistered).replace(std::string(kRegistered).find("\"fx\": 500"), 9, "\"fx\": 0  ")}) {
    const auto parsed = testing::ParseLocalizeJson(line);
    EXPECT_FALSE(parsed.ok()) << line;
    if (!parsed.ok()) {
      EXPECT_EQ(parsed.status().code(), StatusCode::kCorruptData) << parsed.status().ToString();
    }
  }
}

constexpr char kTrackedWithMap[] =
    R"({"frame": "f1.png", "tags": [{"id": 3, "corners": [[1, 2], [3, 4], [5, 6], [7, 8]], "cam_from_tag": )"
    R"({"R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 1]}, "rms_px": 0.2, "reacquired": false}], "source": "map", )"
    R"("state": "tracking", "cam_from_world": {"R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [4, 5, 6]}, )"
    R"("map_inliers": 120, "relocalised": false, "fused_map_points": 0, "metric": false, "units": "model", )"
    R"("search": "regions", "ms": 7.5})";
constexpr char kTrackedTagsOnly[] = R"({"frame": "f2.png", "tags": [], "search": "full_frame", "ms": 3})";

TEST(TrackJson, ReadsFramesWithAndWithoutAMap) {
  auto parsed = testing::ParseTrackJson(std::string("note\n") + kTrackedWithMap + "\n" + kTrackedTagsOnly + "\n");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  ASSERT_EQ(parsed->size(), 2u);
  const testing::TrackedFrame& a = (*parsed)[0];
  EXPECT_EQ(a.frame, "f1.png");
  ASSERT_EQ(a.tags.size(), 1u);
  EXPECT_EQ(a.tags[0].id, 3);
  EXPECT_EQ(a.tags[0].corners[3], Eigen::Vector2d(7, 8));
  EXPECT_EQ(a.source, "map");
  EXPECT_EQ(a.state, "tracking");
  EXPECT_TRUE(a.has_pose);
  EXPECT_EQ(a.t, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(a.map_inliers, 120);
  EXPECT_EQ(a.units, "model");
  EXPECT_DOUBLE_EQ(a.ms, 7.5);
  const testing::TrackedFrame& b = (*parsed)[1];
  EXPECT_TRUE(b.tags.empty());
  EXPECT_TRUE(b.source.empty());
  EXPECT_FALSE(b.has_pose);
}

TEST(TrackJson, RefusesBrokenLines) {
  const std::string with_map = kTrackedWithMap;
  for (const std::string& line :
       {std::string(R"({"frame": "f.png", "ms": 1})"), std::string(R"({"tags": [], "ms": 1})"),
        with_map.substr(0, with_map.find("\"state\"")) + R"("map_inliers": 1, "ms": 1})",
        std::string(with_map).replace(with_map.find("[4, 5, 6]"), 9, "[4, 5]"),
        std::string(with_map).replace(with_map.find("[7, 8]"), 6, "[7]")}) {
    const auto parsed = testing::ParseTrackJson(line);
    EXPECT_FALSE(parsed.ok()) << line;
    if (!parsed.ok()) {
      EXPECT_EQ(parsed.status().code(), StatusCode::kCorruptData) << parsed.status().ToString();
    }
  }
}

}  // namespace
}  // namespace reconar
