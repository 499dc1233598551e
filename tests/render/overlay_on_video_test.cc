// The bunny on a real video frame, placed on tag 12 with the pose that the dataset's reference
// corners give (core/geometry absolute pose, intrinsics from the dataset's SOURCE.txt). Writes PNGs
// to the temp directory for inspection and checks the parts that have ground truth: the rendered
// tag outline passes through the reference corners, the background elsewhere is the frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/geometry/absolute_pose.h"
#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "core/mesh/mesh_io.h"
#include "render/overlay_renderer.h"
#include "tests/support/ar_video.h"
#include "tests/render/gl_test_context.h"

namespace reconar {
namespace {

const std::string kVideo = std::string(RECONAR_SHARED_DATA_DIR) + "/apriltag_ar_video_id12";
const std::string kBunny = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny/reconstruction/bun_zipper.ply";
constexpr double kTagSize = 0.14;  // SOURCE.txt: edge of the black square

// The reference corners a..d of `frame_name` in corners.txt, converted from libapriltag's pixel
// convention (centre of the top-left pixel at (0.5, 0.5)) to CameraIntrinsics' ((0, 0)).
std::vector<Eigen::Vector2d> ReferenceCorners(const std::string& frame_name) {
  std::ifstream file(kVideo + "/corners.txt");
  std::string line;
  while (std::getline(file, line)) {
    std::istringstream fields(line);
    std::string name;
    fields >> name;
    if (name != frame_name) continue;
    std::vector<Eigen::Vector2d> corners(4);
    for (Eigen::Vector2d& corner : corners) {
      fields >> corner.x() >> corner.y();
      corner -= Eigen::Vector2d(0.5, 0.5);
    }
    return corners;
  }
  return {};
}

// The tag corners a..d in the tag frame (x right, y up, z toward the viewer), SOURCE.txt's order.
std::vector<Eigen::Vector3d> TagCorners() {
  const double h = kTagSize / 2;
  return {Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(-h, h, 0)};
}

Result<Rigid3> CamFromTagFromCorners(const std::vector<Eigen::Vector2d>& corners) {
  const CameraIntrinsics intrinsics = testing::ArVideoCamera();
  RadialCamera camera;
  camera.focal = 0.5 * (intrinsics.fx + intrinsics.fy);
  camera.cx = intrinsics.cx;
  camera.cy = intrinsics.cy;
  // RadialCamera has one focal; the pixels are rescaled so fy's axis matches it.
  std::vector<Eigen::Vector2d> pixels = corners;
  for (Eigen::Vector2d& pixel : pixels) {
    pixel.x() = (pixel.x() - intrinsics.cx) * camera.focal / intrinsics.fx + intrinsics.cx;
    pixel.y() = (pixel.y() - intrinsics.cy) * camera.focal / intrinsics.fy + intrinsics.cy;
  }
  AbsolutePoseOptions options;
  options.min_inliers = 4;
  options.max_error_px = 3.0;
  RECONAR_ASSIGN_OR_RETURN(AbsolutePoseResult pose, EstimateAbsolutePose(pixels, TagCorners(), camera, options));
  if (!pose.success()) return FailedPrecondition("pose from corners: " + pose.reason);
  return pose.cam_from_world;  // the tag's corners are the world points: cam_from_tag
}

std::string TempPath(const std::string& name) {
  const char* directory = std::getenv("TMPDIR");
  return std::string(directory != nullptr && directory[0] != '\0' ? directory : "/tmp") + "/" + name;
}

TEST(OverlayOnVideoTest, BunnyOnTag12WithThePoseOfTheReferenceCorners) {
  ASSERT_NE(testing::SharedSurfacelessContext(), nullptr);
  auto frame = ReadImage(kVideo + "/frames/frame0000.jpg");
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  auto bunny = ReadPly(kBunny);
  ASSERT_TRUE(bunny.ok()) << bunny.status().ToString();
  const std::vector<Eigen::Vector2d> corners = ReferenceCorners("frame0000.jpg");
  ASSERT_EQ(corners.size(), 4u);
  auto cam_from_tag = CamFromTagFromCorners(corners);
  ASSERT_TRUE(cam_from_tag.ok()) << cam_from_tag.status().ToString();
  const CameraIntrinsics intrinsics = testing::ArVideoCamera();
  double worst_reprojection = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d projected = intrinsics.Project(*cam_from_tag * TagCorners()[i]);
    worst_reprojection = std::max(worst_reprojection, (projected - corners[i]).norm());
  }
  EXPECT_LT(worst_reprojection, 2.0);
  std::printf("cam_from_tag t = (%.4f, %.4f, %.4f) m, corner reprojection <= %.3f px\n", cam_from_tag->translation.x(),
              cam_from_tag->translation.y(), cam_from_tag->translation.z(), worst_reprojection);

  OverlayRendererOptions options;
  options.width = frame->rgb.width();
  options.height = frame->rgb.height();
  options.samples = 4;
  auto renderer = OverlayRenderer::Create(options);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();

  // 1. The tag outline alone (no anti-aliasing blur of the test colour: a thin line).
  {
    OverlayRendererOptions plain = options;
    plain.samples = 0;
    auto outline_renderer = OverlayRenderer::Create(plain);
    ASSERT_TRUE(outline_renderer.ok());
    TagAxesStyle outline_only;
    outline_only.draw_axes = false;
    outline_only.line_width_px = 1.0f;
    ASSERT_TRUE((*outline_renderer)->BeginFrame().ok());
    ASSERT_TRUE((*outline_renderer)->DrawBackground(frame->rgb.view(), 3).ok());
    ASSERT_TRUE((*outline_renderer)->DrawTagAxes(intrinsics, *cam_from_tag, kTagSize, outline_only).ok());
    Image<uint8_t> outlined;
    ASSERT_TRUE((*outline_renderer)->ReadRgb(&outlined).ok());
    // Each reference corner has a yellow outline pixel within 1.5 px.
    for (const Eigen::Vector2d& corner : corners) {
      double nearest = 1e9;
      for (int y = int(corner.y()) - 4; y <= int(corner.y()) + 4; ++y) {
        for (int x = int(corner.x()) - 4; x <= int(corner.x()) + 4; ++x) {
          const uint8_t* p = outlined.row(y) + 3 * x;
          if (p[0] == 255 && p[1] == 255 && p[2] == 0)
            nearest = std::min(nearest, (Eigen::Vector2d(x, y) - corner).norm());
        }
      }
      EXPECT_LT(nearest, 1.5) << "reference corner " << corner.transpose();
    }
    // Away from the tag the frame is untouched.
    EXPECT_EQ(std::memcmp(outlined.row(5), frame->rgb.row(5), 3 * 640), 0);
    EXPECT_TRUE(WritePng(TempPath("reconar_overlay_outline_frame0000.png"), outlined.view(), 3).ok());
  }

  // 2. The bunny standing on the tag at two sizes (cf. the paper's Fig. 14: the same model cup-sized
  // and larger), with the tag axes.
  auto drawable = MeshDrawable::Upload(*bunny);
  ASSERT_TRUE(drawable.ok());
  for (double height : {0.10, 0.30}) {
    auto placement = ModelPlacement::StandingOnTag(*bunny, height);
    ASSERT_TRUE(placement.ok());
    ASSERT_TRUE((*renderer)->BeginFrame().ok());
    ASSERT_TRUE((*renderer)->DrawBackground(frame->rgb.view(), 3).ok());
    ASSERT_TRUE((*renderer)->DrawMesh(*drawable, intrinsics, CamFromModel(*cam_from_tag, *placement)).ok());
    ASSERT_TRUE((*renderer)->DrawTagAxes(intrinsics, *cam_from_tag, kTagSize).ok());
    Image<uint8_t> overlay;
    ASSERT_TRUE((*renderer)->ReadRgb(&overlay).ok());
    // The bunny covers the point of the tag plane just behind the tag centre... and nothing
    // changed in the top-left corner of the frame.
    const Eigen::Vector2d body = intrinsics.Project(*cam_from_tag * Eigen::Vector3d(0, 0, 0.4 * height));
    const uint8_t* drawn = overlay.row(int(body.y())) + 3 * int(body.x());
    const uint8_t* original = frame->rgb.row(int(body.y())) + 3 * int(body.x());
    EXPECT_NE(std::memcmp(drawn, original, 3), 0) << "nothing drawn at the bunny's body " << body.transpose();
    EXPECT_EQ(std::memcmp(overlay.row(2), frame->rgb.row(2), 3 * 100), 0);
    char name[96];
    std::snprintf(name, sizeof(name), "reconar_overlay_bunny_%.0fcm_frame0000.png", height * 100);
    const Status written = WritePng(TempPath(name), overlay.view(), 3);
    EXPECT_TRUE(written.ok()) << written.ToString();
    std::printf("wrote %s\n", TempPath(name).c_str());
  }
}

}  // namespace
}  // namespace reconar
