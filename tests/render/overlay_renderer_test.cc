// The overlay renderer against independent ground truth: CameraIntrinsics::Project for where
// things land, a real video frame for the background, a real scanned mesh (Stanford bunny) for
// silhouettes.
#include "render/overlay_renderer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/io/image_io.h"
#include "core/mesh/mesh_io.h"
#include "tests/render/gl_test_context.h"
#include "tests/render/test_cameras.h"
#include "tests/support/allocation_counter.h"

namespace reconar {
namespace {

using Rgb = std::array<uint8_t, 3>;

const std::string kData = RECONAR_SHARED_DATA_DIR;
const std::string kFrame = kData + "/apriltag_ar_video_id12/frames/frame0000.jpg";
const std::string kBunny = kData + "/stanford_bunny/reconstruction/bun_zipper.ply";

using testing::OffCentreCamera;

Rgb PixelAt(const Image<uint8_t>& image, int x, int y) {
  const uint8_t* p = image.row(y) + 3 * x;
  return {p[0], p[1], p[2]};
}

struct PixelBox {
  int min_x = 1 << 30, min_y = 1 << 30, max_x = -1, max_y = -1;
  int count = 0;
  double sum_x = 0.0, sum_y = 0.0;
  void Add(int x, int y) {
    min_x = std::min(min_x, x);
    max_x = std::max(max_x, x);
    min_y = std::min(min_y, y);
    max_y = std::max(max_y, y);
    sum_x += x;
    sum_y += y;
    ++count;
  }
};

template <typename Predicate>
PixelBox BoxOf(const Image<uint8_t>& image, Predicate matches) {
  PixelBox box;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      if (matches(PixelAt(image, x, y))) box.Add(x, y);
    }
  }
  return box;
}

// A camera-facing square (two triangles) of uniform colour, appended to `mesh`.
void AddSquare(const Eigen::Vector3f& centre, float half_size, const std::array<uint8_t, 4>& color, Mesh* mesh) {
  const uint32_t base = static_cast<uint32_t>(mesh->positions.size());
  for (const auto& corner :
       {Eigen::Vector2f(-1, -1), Eigen::Vector2f(1, -1), Eigen::Vector2f(1, 1), Eigen::Vector2f(-1, 1)}) {
    mesh->positions.push_back(centre + Eigen::Vector3f(corner.x() * half_size, corner.y() * half_size, 0.0f));
    mesh->colors.push_back(color);
  }
  mesh->triangles.push_back({base, base + 1, base + 2});
  mesh->triangles.push_back({base, base + 2, base + 3});
}

class OverlayRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(testing::SharedSurfacelessContext(), nullptr);
    ASSERT_TRUE(testing::SharedSurfacelessContext()->MakeCurrent().ok());
  }

  std::unique_ptr<OverlayRenderer> MakeRenderer(int width, int height, int samples = 0) {
    OverlayRendererOptions options;
    options.width = width;
    options.height = height;
    options.samples = samples;
    auto renderer = OverlayRenderer::Create(options);
    EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
    return renderer.ok() ? std::move(renderer).value() : nullptr;
  }
};

// Squares at known camera-frame positions: every edge of each rendered square must sit where
// CameraIntrinsics::Project puts it. GL covers the pixels whose centres lie inside, so the first
// covered column is ceil(u_left) and the last is ceil(u_right) - 1 (likewise rows): this pins the
// projection to the rasteriser's sub-pixel precision, far tighter than the 0.5 px asked for.
TEST_F(OverlayRendererTest, SquaresLandWhereTheIntrinsicsProjectThem) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Mesh squares;
  std::vector<Eigen::Vector3f> centres;
  std::vector<float> half_sizes;
  for (int i = 0; i < 12; ++i) {
    const float depth = 0.7f + 0.37f * static_cast<float>(i);
    const Eigen::Vector3f centre((-0.38f + 0.075f * static_cast<float>(i)) * depth,
                                 (-0.3f + 0.173f * static_cast<float>(i % 4)) * depth, depth);
    const float half = 0.013f * depth + 0.0021f * static_cast<float>(i);
    centres.push_back(centre);
    half_sizes.push_back(half);
    AddSquare(centre, half, {static_cast<uint8_t>(20 * (i + 1)), static_cast<uint8_t>(255 - 20 * i), 77, 255},
              &squares);
  }
  auto drawable = MeshDrawable::Upload(squares);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  MeshStyle unlit;
  unlit.shading = false;
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  ASSERT_EQ(rendered.width(), 640);
  ASSERT_EQ(rendered.height(), 480);

  int edges_checked = 0;
  double worst_edge_error = 0.0;
  for (int i = 0; i < 12; ++i) {
    const Rgb color = {static_cast<uint8_t>(20 * (i + 1)), static_cast<uint8_t>(255 - 20 * i), 77};
    const PixelBox box = BoxOf(rendered, [&](const Rgb& p) { return p == color; });
    const Eigen::Vector3d c = centres[i].cast<double>();
    const double h = half_sizes[i];
    const Eigen::Vector2d top_left = intrinsics.Project(c + Eigen::Vector3d(-h, -h, 0));
    const Eigen::Vector2d bottom_right = intrinsics.Project(c + Eigen::Vector3d(h, h, 0));
    ASSERT_GT(box.count, 0) << "square " << i;
    // Edge positions in pixel-centre coordinates and the covered pixel range they imply.
    const double edges[4] = {top_left.x(), bottom_right.x(), top_left.y(), bottom_right.y()};
    const int covered[4] = {box.min_x, box.max_x + 1, box.min_y, box.max_y + 1};
    for (int e = 0; e < 4; ++e) {
      worst_edge_error = std::max(worst_edge_error, std::abs(covered[e] - 0.5 - edges[e]));
      const double fraction = edges[e] - std::floor(edges[e]);
      if (fraction < 0.01 || fraction > 0.99) continue;  // within the rasteriser's precision of a centre
      EXPECT_EQ(covered[e], static_cast<int>(std::ceil(edges[e])))
          << "square " << i << " edge " << e << " at " << edges[e];
      ++edges_checked;
    }
    // The centroid of the covered pixels is the projected centre of the square.
    const Eigen::Vector2d centre_px = intrinsics.Project(c);
    EXPECT_NEAR(box.sum_x / box.count, centre_px.x(), 0.5) << "square " << i;
    EXPECT_NEAR(box.sum_y / box.count, centre_px.y(), 0.5) << "square " << i;
  }
  EXPECT_GE(edges_checked, 40);
  EXPECT_LE(worst_edge_error, 1.0);
  std::printf("edges checked: %d, largest |covered edge - projected edge| = %.3f px (pixel quantisation)\n",
              edges_checked, worst_edge_error);
}

// Single-pixel points (a point cloud): each lands on the pixel containing its projection.
TEST_F(OverlayRendererTest, PointCloudPointsLandOnTheirProjectedPixels) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Mesh cloud;
  for (int i = 0; i < 40; ++i) {
    const float depth = 0.5f + 0.21f * static_cast<float>(i);
    cloud.positions.emplace_back((-0.4f + 0.0197f * static_cast<float>(i)) * depth,
                                 (0.3f - 0.0153f * static_cast<float>(i)) * depth, depth);
  }
  auto drawable = MeshDrawable::Upload(cloud);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  ASSERT_TRUE(drawable->is_point_cloud());
  MeshStyle style;
  style.point_size_px = 1.0f;
  style.color = {1.0f, 1.0f, 1.0f};
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), style).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  int checked = 0;
  for (const Eigen::Vector3f& point : cloud.positions) {
    const Eigen::Vector2d pixel = intrinsics.Project(point.cast<double>());
    const double fx = pixel.x() - std::floor(pixel.x());
    const double fy = pixel.y() - std::floor(pixel.y());
    if (std::abs(fx - 0.5) < 0.02 || std::abs(fy - 0.5) < 0.02) continue;  // on a pixel border
    const int x = static_cast<int>(std::lround(pixel.x()));
    const int y = static_cast<int>(std::lround(pixel.y()));
    EXPECT_EQ(PixelAt(rendered, x, y), (Rgb{255, 255, 255})) << "point projected to " << pixel.transpose();
    ++checked;
  }
  EXPECT_GE(checked, 30);
  const PixelBox lit = BoxOf(rendered, [](const Rgb& p) { return p[0] != 0; });
  EXPECT_EQ(lit.count, static_cast<int>(cloud.positions.size()));  // one pixel each, nothing else
}

// A real video frame drawn as the background reads back unchanged; strided and padded views
// (through GL_UNPACK_ROW_LENGTH, GL_UNPACK_ALIGNMENT, and row by row) give the same pixels.
TEST_F(OverlayRendererTest, BackgroundReadsBackAsTheFrame) {
  auto frame = ReadImage(kFrame);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  const Image<uint8_t>& rgb = frame->rgb;
  auto renderer = MakeRenderer(rgb.width(), rgb.height());
  ASSERT_NE(renderer, nullptr);
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawBackground(rgb.view(), 3).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  int largest_difference = 0;
  for (size_t i = 0; i < rgb.size_bytes(); ++i) {
    largest_difference = std::max(largest_difference, std::abs(int(rendered.data()[i]) - int(rgb.data()[i])));
  }
  EXPECT_LE(largest_difference, 1);
  std::printf("background: largest difference %d over %d x %d\n", largest_difference, rgb.width(), rgb.height());

  // A 333 x 240 crop three ways: the parent's stride (multiple of 3), padded to a multiple of 2
  // (alignment), padded by 5 (neither: uploaded row by row).
  const int crop_width = 333;
  const int crop_height = 240;
  auto crop_renderer = MakeRenderer(crop_width, crop_height);
  ASSERT_NE(crop_renderer, nullptr);
  const ImageView<const uint8_t> in_parent = rgb.view().sub(3 * 101, 77, 3 * crop_width, crop_height);
  for (int padding : {-1, 1, 5}) {
    std::vector<uint8_t> storage;
    ImageView<const uint8_t> view = in_parent;
    if (padding >= 0) {
      const ptrdiff_t stride = 3 * crop_width + padding;
      storage.assign(static_cast<size_t>(stride) * crop_height, 0xAB);
      for (int y = 0; y < crop_height; ++y) std::memcpy(&storage[y * stride], in_parent.row(y), 3 * crop_width);
      view = ImageView<const uint8_t>(3 * crop_width, crop_height, stride, storage.data());
    }
    ASSERT_TRUE(crop_renderer->BeginFrame().ok());
    ASSERT_TRUE(crop_renderer->DrawBackground(view, 3).ok());
    Image<uint8_t> crop;
    ASSERT_TRUE(crop_renderer->ReadRgb(&crop).ok());
    int worst = 0;
    for (int y = 0; y < crop_height; ++y) {
      for (int x = 0; x < 3 * crop_width; ++x)
        worst = std::max(worst, std::abs(int(crop.row(y)[x]) - int(in_parent.row(y)[x])));
    }
    EXPECT_LE(worst, 1) << "padding " << padding;
  }
}

// The Stanford bunny (69,451 triangles) in front of the camera: its silhouette's bounding box is
// the bounding box of its projected vertices.
TEST_F(OverlayRendererTest, BunnySilhouetteMatchesItsProjectedVertices) {
  auto bunny = ReadPly(kBunny);
  ASSERT_TRUE(bunny.ok()) << bunny.status().ToString();
  ASSERT_EQ(bunny->triangles.size(), 69451u);
  const CameraIntrinsics intrinsics = OffCentreCamera();
  // Bunny y up -> camera y down: turn it 180 degrees about x, then 0.45 m in front of the camera.
  Eigen::Matrix4d cam_from_model = Eigen::Matrix4d::Identity();
  cam_from_model.topLeftCorner<3, 3>() =
      (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  cam_from_model.topRightCorner<3, 1>() = Eigen::Vector3d(0.03, 0.08, 0.45);
  double min_u = 1e9, max_u = -1e9, min_v = 1e9, max_v = -1e9;
  for (const Eigen::Vector3f& p : bunny->positions) {
    const Eigen::Vector3d cam = (cam_from_model * p.cast<double>().homogeneous()).head<3>();
    const Eigen::Vector2d pixel = intrinsics.Project(cam);
    min_u = std::min(min_u, pixel.x());
    max_u = std::max(max_u, pixel.x());
    min_v = std::min(min_v, pixel.y());
    max_v = std::max(max_v, pixel.y());
  }
  ASSERT_GT(min_u, 0.0);
  ASSERT_LT(max_u, 639.0);
  ASSERT_GT(min_v, 0.0);
  ASSERT_LT(max_v, 479.0);

  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  auto drawable = MeshDrawable::Upload(*bunny);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, cam_from_model).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const PixelBox silhouette = BoxOf(rendered, [](const Rgb& p) { return p[0] != 0 || p[1] != 0 || p[2] != 0; });
  std::printf("bunny: silhouette x %d..%d y %d..%d, projected vertices u %.2f..%.2f v %.2f..%.2f\n", silhouette.min_x,
              silhouette.max_x, silhouette.min_y, silhouette.max_y, min_u, max_u, min_v, max_v);
  EXPECT_NEAR(silhouette.min_x, min_u, 1.0);
  EXPECT_NEAR(silhouette.max_x, max_u, 1.0);
  EXPECT_NEAR(silhouette.min_y, min_v, 1.0);
  EXPECT_NEAR(silhouette.max_y, max_v, 1.0);
  // Shaded: the headlight makes faces toward the camera brighter than grazing ones.
  const PixelBox bright = BoxOf(rendered, [](const Rgb& p) { return p[0] > 180; });
  const PixelBox dark = BoxOf(rendered, [](const Rgb& p) { return p[0] > 0 && p[0] < 120; });
  EXPECT_GT(bright.count, 1000);
  EXPECT_GT(dark.count, 50);
}

// Depth test: a near square in front of a larger far one wins wherever they overlap, whatever
// the drawing order.
TEST_F(OverlayRendererTest, NearSurfacesHideFarOnes) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  for (bool near_first : {true, false}) {
    Mesh squares;
    const Eigen::Vector3f on_axis(0.0f, 0.0f, 1.0f);
    if (near_first) AddSquare(on_axis * 1.0f, 0.05f, {255, 0, 0, 255}, &squares);
    AddSquare(on_axis * 2.0f, 0.3f, {0, 255, 0, 255}, &squares);
    if (!near_first) AddSquare(on_axis * 1.0f, 0.05f, {255, 0, 0, 255}, &squares);
    auto drawable = MeshDrawable::Upload(squares);
    ASSERT_TRUE(drawable.ok());
    MeshStyle unlit;
    unlit.shading = false;
    ASSERT_TRUE(renderer->BeginFrame().ok());
    ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
    Image<uint8_t> rendered;
    ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
    const Eigen::Vector2d centre = intrinsics.Project(Eigen::Vector3d(0, 0, 1));
    const Eigen::Vector2d far_only = intrinsics.Project(Eigen::Vector3d(0.2, 0.2, 2.0));
    EXPECT_EQ(PixelAt(rendered, int(std::lround(centre.x())), int(std::lround(centre.y()))), (Rgb{255, 0, 0}));
    EXPECT_EQ(PixelAt(rendered, int(std::lround(far_only.x())), int(std::lround(far_only.y()))), (Rgb{0, 255, 0}));
  }
}

// A texture in pages: each square takes its colour from its own page (white vertex colours
// times the texture, as glTF has it), whichever page comes first.
TEST_F(OverlayRendererTest, EachTexturePageTexturesItsOwnTriangles) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Mesh squares;
  AddSquare(Eigen::Vector3f(-0.3f, 0.0f, 2.0f), 0.2f, {255, 255, 255, 255}, &squares);
  AddSquare(Eigen::Vector3f(0.3f, 0.0f, 2.0f), 0.2f, {255, 255, 255, 255}, &squares);
  for (size_t i = 0; i < squares.positions.size(); ++i) squares.texcoords.emplace_back(0.5f, 0.5f);
  auto plain = [](int width, int height, Rgb colour) {
    Image<uint8_t> image(width, height, 3);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) std::copy(colour.begin(), colour.end(), image.row(y) + 3 * x);
    }
    return image;
  };
  std::vector<TexturePage> pages;
  pages.push_back({0, plain(64, 64, {200, 30, 30})});
  pages.push_back({2, plain(32, 16, {30, 30, 200})});
  auto drawable = MeshDrawable::Upload(squares, &pages);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  EXPECT_TRUE(drawable->has_texture());
  MeshStyle unlit;
  unlit.shading = false;
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const Eigen::Vector2d left = intrinsics.Project(Eigen::Vector3d(-0.3, 0.0, 2.0));
  const Eigen::Vector2d right = intrinsics.Project(Eigen::Vector3d(0.3, 0.0, 2.0));
  EXPECT_EQ(PixelAt(rendered, int(std::lround(left.x())), int(std::lround(left.y()))), (Rgb{200, 30, 30}));
  EXPECT_EQ(PixelAt(rendered, int(std::lround(right.x())), int(std::lround(right.y()))), (Rgb{30, 30, 200}));

  std::vector<TexturePage> out_of_order;
  out_of_order.push_back({1, plain(8, 8, {0, 0, 0})});
  EXPECT_EQ(MeshDrawable::Upload(squares, &out_of_order).status().code(), StatusCode::kInvalidArgument);
}

// A semi-transparent mesh (a design over the as-built) blends over what is drawn, is hidden by what
// stands in front of it, and hides nothing drawn after it.
TEST_F(OverlayRendererTest, SemiTransparentMeshesBlendAndHideNothing) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  const Eigen::Vector3f on_axis(0.0f, 0.0f, 1.0f);
  Mesh far_green, veil, behind_red;
  AddSquare(on_axis * 3.0f, 0.6f, {0, 255, 0, 255}, &far_green);
  AddSquare(on_axis * 2.0f, 0.3f, {0, 0, 255, 255}, &veil);
  AddSquare(on_axis * 2.5f, 0.05f, {255, 0, 0, 255}, &behind_red);
  auto green = MeshDrawable::Upload(far_green), blue = MeshDrawable::Upload(veil), red = MeshDrawable::Upload(behind_red);
  ASSERT_TRUE(green.ok() && blue.ok() && red.ok());
  MeshStyle unlit;
  unlit.shading = false;
  MeshStyle half = unlit;
  half.opacity = 0.5f;
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*green, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  ASSERT_TRUE(renderer->DrawMesh(*blue, intrinsics, Eigen::Matrix4d::Identity(), half).ok());
  ASSERT_TRUE(renderer->DrawMesh(*red, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const auto pixel = [&](const Eigen::Vector3d& point) {
    const Eigen::Vector2d p = intrinsics.Project(point);
    return PixelAt(rendered, int(std::lround(p.x())), int(std::lround(p.y())));
  };
  const Rgb blended = pixel({0.15, 0.15, 2.0});  // the veil over the green
  EXPECT_NEAR(blended[0], 0, 2);
  EXPECT_NEAR(blended[1], 128, 2);
  EXPECT_NEAR(blended[2], 128, 2);
  EXPECT_EQ(pixel({0.0, 0.0, 2.5}), (Rgb{255, 0, 0}));  // behind the veil but drawn after it: whole
  EXPECT_EQ(pixel({0.5, 0.5, 3.0}), (Rgb{0, 255, 0}));  // beyond the veil: untouched
}

// A mesh of more than 65536 vertices (32-bit indices) draws the triangles whose indices are large.
TEST_F(OverlayRendererTest, MeshesBeyond16BitIndicesDraw) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Mesh mesh;
  mesh.positions.assign(70000, Eigen::Vector3f(0.0f, 0.0f, 50.0f));  // unused filler
  mesh.colors.assign(70000, {0, 0, 0, 255});
  AddSquare(Eigen::Vector3f(0.0f, 0.0f, 1.0f), 0.05f, {0, 200, 100, 255}, &mesh);
  auto drawable = MeshDrawable::Upload(mesh);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  MeshStyle unlit;
  unlit.shading = false;
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const Eigen::Vector2d centre = intrinsics.Project(Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(PixelAt(rendered, int(std::lround(centre.x())), int(std::lround(centre.y()))), (Rgb{0, 200, 100}));
}

// Vertex normals drive the headlight shade: a square whose normals face the camera shows the full
// colour, one whose normals are perpendicular to the view shows the ambient floor (0.2).
TEST_F(OverlayRendererTest, VertexNormalsDriveTheShading) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Mesh squares;
  AddSquare(Eigen::Vector3f(-0.2f, 0.0f, 1.0f), 0.05f, {255, 255, 255, 255}, &squares);
  AddSquare(Eigen::Vector3f(0.2f, 0.0f, 1.0f), 0.05f, {255, 255, 255, 255}, &squares);
  squares.colors.clear();
  for (int i = 0; i < 8; ++i) {
    // Toward the viewer: the camera sits at the origin, the squares at z = 1, so -z; then +x.
    squares.normals.push_back(i < 4 ? Eigen::Vector3f(0, 0, -1) : Eigen::Vector3f(1, 0, 0));
  }
  auto drawable = MeshDrawable::Upload(squares);
  ASSERT_TRUE(drawable.ok()) << drawable.status().ToString();
  ASSERT_TRUE(drawable->has_normals());
  MeshStyle style;
  style.color = {1.0f, 0.5f, 0.25f};
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), style).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const Eigen::Vector2d facing = intrinsics.Project(Eigen::Vector3d(-0.2, 0, 1));
  const Eigen::Vector2d grazing = intrinsics.Project(Eigen::Vector3d(0.2, 0, 1));
  const Rgb lit = PixelAt(rendered, int(std::lround(facing.x())), int(std::lround(facing.y())));
  const Rgb dim = PixelAt(rendered, int(std::lround(grazing.x())), int(std::lround(grazing.y())));
  // At the square's centre the view direction is (0.2, 0, -1)/|.|: |n . v| = 0.981 and 0.196.
  EXPECT_NEAR(lit[0], 255 * (0.2 + 0.8 * 0.9806), 2);
  EXPECT_NEAR(lit[1], 127.5 * (0.2 + 0.8 * 0.9806), 2);
  EXPECT_NEAR(dim[0], 255 * (0.2 + 0.8 * 0.1961), 2);
}

// Tag axes: red along x, green along y, blue along z, the yellow outline through the corners.
TEST_F(OverlayRendererTest, TagAxesAndOutlineLandOnTheTagFrame) {
  const CameraIntrinsics intrinsics = OffCentreCamera();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  Rigid3 cam_from_tag;
  // The tag faces the camera (tag z toward the viewer = camera -z), tilted a little.
  cam_from_tag.rotation = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()))
                              .toRotationMatrix();
  cam_from_tag.translation = Eigen::Vector3d(0.02, -0.01, 0.6);
  const double size = 0.14;
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawTagAxes(intrinsics, cam_from_tag, size).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  // The colour found within 1 px of the projection of a tag-frame point.
  auto color_near = [&](const Eigen::Vector3d& tag_point, const Rgb& wanted) {
    const Eigen::Vector2d pixel = intrinsics.Project(cam_from_tag * tag_point);
    const int x0 = int(std::lround(pixel.x()));
    const int y0 = int(std::lround(pixel.y()));
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (PixelAt(rendered, x0 + dx, y0 + dy) == wanted) return true;
      }
    }
    return false;
  };
  EXPECT_TRUE(color_near(Eigen::Vector3d(0.6 * size, 0, 0), Rgb{255, 0, 0}));
  EXPECT_TRUE(color_near(Eigen::Vector3d(0, 0.6 * size, 0), Rgb{0, 255, 0}));
  EXPECT_TRUE(color_near(Eigen::Vector3d(0, 0, 0.6 * size), Rgb{0, 0, 255}));
  for (const auto& edge_middle : {Eigen::Vector3d(0, -size / 2, 0), Eigen::Vector3d(size / 2, 0.02, 0),
                                  Eigen::Vector3d(-0.03, size / 2, 0), Eigen::Vector3d(-size / 2, -0.04, 0)}) {
    EXPECT_TRUE(color_near(edge_middle, Rgb{255, 255, 0})) << edge_middle.transpose();
  }
  EXPECT_EQ(renderer->DrawTagAxes(intrinsics, cam_from_tag, -1.0).code(), StatusCode::kInvalidArgument);
}

// After the first frame, a frame (upload + mesh + axes + readback) makes no heap allocation.
TEST_F(OverlayRendererTest, SteadyStateFramesDoNotAllocate) {
  auto frame = ReadImage(kFrame);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  auto bunny = ReadPly(kBunny);
  ASSERT_TRUE(bunny.ok()) << bunny.status().ToString();
  auto renderer = MakeRenderer(640, 480);
  ASSERT_NE(renderer, nullptr);
  auto drawable = MeshDrawable::Upload(*bunny);
  ASSERT_TRUE(drawable.ok());
  const CameraIntrinsics intrinsics = OffCentreCamera();
  Rigid3 cam_from_tag;
  cam_from_tag.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  cam_from_tag.translation = Eigen::Vector3d(0, 0, 0.6);
  auto placement = ModelPlacement::StandingOnTag(*bunny, 0.1);
  ASSERT_TRUE(placement.ok());
  const Eigen::Matrix4d cam_from_model = CamFromModel(cam_from_tag, *placement);
  Image<uint8_t> rendered;
  auto render_frame = [&]() {
    bool ok = renderer->BeginFrame().ok();
    ok = ok && renderer->DrawBackground(frame->rgb.view(), 3).ok();
    ok = ok && renderer->DrawMesh(*drawable, intrinsics, cam_from_model).ok();
    ok = ok && renderer->DrawTagAxes(intrinsics, cam_from_tag, 0.14).ok();
    ok = ok && renderer->ReadRgb(&rendered).ok();
    return ok;
  };
  ASSERT_TRUE(render_frame());
  ASSERT_TRUE(render_frame());
  long allocations = 0;
  {
    testing::NoAllocationScope no_allocation;
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(render_frame());
    allocations = no_allocation.allocations();
  }
  EXPECT_EQ(allocations, 0);
}

TEST_F(OverlayRendererTest, BadInputIsReported) {
  auto renderer = MakeRenderer(64, 48);
  ASSERT_NE(renderer, nullptr);
  std::vector<uint8_t> pixels(64 * 48 * 3, 0);
  EXPECT_EQ(renderer->DrawBackground(ImageView<const uint8_t>(64 * 3 - 1, 48, 64 * 3, pixels.data()), 3).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(renderer->DrawBackground(ImageView<const uint8_t>(64 * 3, 48, 64 * 3, pixels.data()), 2).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(renderer->DrawBackground(ImageView<const uint8_t>(), 3).code(), StatusCode::kInvalidArgument);

  Mesh broken;
  broken.positions = {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(1, 0, 1), Eigen::Vector3f(0, 1, 1)};
  broken.triangles = {{0, 1, 3}};
  auto drawable = MeshDrawable::Upload(broken);
  ASSERT_FALSE(drawable.ok());
  EXPECT_EQ(drawable.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(MeshDrawable::Upload(Mesh()).status().code(), StatusCode::kInvalidArgument);

  OverlayRendererOptions options;
  options.width = 0;
  EXPECT_EQ(OverlayRenderer::Create(options).status().code(), StatusCode::kInvalidArgument);
  options.width = 1 << 20;
  EXPECT_EQ(OverlayRenderer::Create(options).status().code(), StatusCode::kInvalidArgument);
}

TEST_F(OverlayRendererTest, ShaderErrorsCarryTheDriverLog) {
  auto program =
      ShaderProgram::Build("broken", "#version 300 es\nvoid main() { gl_Position = undefined_thing; }\n",
                           "#version 300 es\nprecision highp float;\nout vec4 c;\nvoid main() { c = vec4(1); }\n");
  ASSERT_FALSE(program.ok());
  EXPECT_NE(program.status().message().find("broken vertex shader: compile failed"), std::string::npos);
  EXPECT_NE(program.status().message().find("undefined_thing"), std::string::npos) << program.status().message();
}

// Multisampling resolves into the same image size and keeps the overlay where it was.
TEST_F(OverlayRendererTest, MultisampledTargetResolves) {
  auto renderer = MakeRenderer(640, 480, 4);
  ASSERT_NE(renderer, nullptr);
  Mesh square;
  AddSquare(Eigen::Vector3f(0, 0, 1), 0.1f, {255, 255, 255, 255}, &square);
  auto drawable = MeshDrawable::Upload(square);
  ASSERT_TRUE(drawable.ok());
  MeshStyle unlit;
  unlit.shading = false;
  const CameraIntrinsics intrinsics = OffCentreCamera();
  ASSERT_TRUE(renderer->BeginFrame().ok());
  ASSERT_TRUE(renderer->DrawMesh(*drawable, intrinsics, Eigen::Matrix4d::Identity(), unlit).ok());
  Image<uint8_t> rendered;
  ASSERT_TRUE(renderer->ReadRgb(&rendered).ok());
  const PixelBox white = BoxOf(rendered, [](const Rgb& p) { return p[0] >= 128; });  // more than half covered
  const Eigen::Vector2d top_left = intrinsics.Project(Eigen::Vector3d(-0.1, -0.1, 1));
  const Eigen::Vector2d bottom_right = intrinsics.Project(Eigen::Vector3d(0.1, 0.1, 1));
  EXPECT_NEAR(white.min_x, top_left.x(), 1.0);
  EXPECT_NEAR(white.max_x, bottom_right.x(), 1.0);
  EXPECT_NEAR(white.min_y, top_left.y(), 1.0);
  EXPECT_NEAR(white.max_y, bottom_right.y(), 1.0);
  // Partly covered edge pixels are blended (anti-aliased): some grey exists.
  const PixelBox grey = BoxOf(rendered, [](const Rgb& p) { return p[0] > 0 && p[0] < 255; });
  EXPECT_GT(grey.count, 0);
}

}  // namespace
}  // namespace reconar
