// Texturing against a known surface colour: photos of a cube whose colour is a function of the
// surface point are rendered by ray casting; the textured cube, sampled through its texture
// coordinates and atlas, must give back that function.
#include "core/texture/texture_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "core/base/image_sampling.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar {
namespace {

// A cube [-0.5, 0.5]^3 cut into n x n squares per side, counter-clockwise from outside.
Mesh SubdividedCube(int n) {
  Mesh mesh;
  std::map<std::array<int, 3>, uint32_t> index_of;
  auto vertex = [&](std::array<int, 3> key) {
    const auto [it, added] = index_of.emplace(key, static_cast<uint32_t>(mesh.positions.size()));
    if (added) mesh.positions.emplace_back(key[0] / float(n) - 0.5f, key[1] / float(n) - 0.5f, key[2] / float(n) - 0.5f);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {0, n}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          std::array<uint32_t, 4> corner;
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int k = 0; k < 4; ++k) {
            std::array<int, 3> key;
            key[axis] = side;
            key[(axis + 1) % 3] = i + di[k];
            key[(axis + 2) % 3] = j + dj[k];
            corner[k] = vertex(key);
          }
          for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{corner[0], corner[1], corner[2]},
                                                     std::array<uint32_t, 3>{corner[0], corner[2], corner[3]}}) {
            const Eigen::Vector3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
            const bool outward = (b - a).cross(c - a).dot((a + b + c) / 3.0f) > 0.0f;
            mesh.triangles.push_back(outward ? t : std::array<uint32_t, 3>{t[0], t[2], t[1]});
          }
        }
      }
    }
  }
  return mesh;
}

// A sphere of radius 0.6: an octahedron whose triangles are split in four `levels` times.
Mesh Sphere(int levels) {
  Mesh mesh;
  mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle_of;
    auto middle = [&](uint32_t a, uint32_t b) {
      const auto [it, added] = middle_of.emplace(std::minmax(a, b), static_cast<uint32_t>(mesh.positions.size()));
      if (added) mesh.positions.push_back((mesh.positions[a] + mesh.positions[b]).normalized());
      return it->second;
    };
    std::vector<std::array<uint32_t, 3>> split;
    for (const auto& t : mesh.triangles) {
      const uint32_t ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
      split.push_back({t[0], ab, ca});
      split.push_back({ab, t[1], bc});
      split.push_back({ca, bc, t[2]});
      split.push_back({ab, bc, ca});
    }
    mesh.triangles = split;
  }
  for (Eigen::Vector3f& p : mesh.positions) p *= 0.6f;
  return mesh;
}

// The surface colour: smooth stripes in three directions.
Eigen::Vector3f TrueColour(const Eigen::Vector3d& p) {
  const double tau = 2.0 * M_PI;
  return Eigen::Vector3f(static_cast<float>(128 + 90 * std::sin(tau * (p.x() + 0.3 * p.y()) / 0.9)),
                         static_cast<float>(128 + 90 * std::sin(tau * (p.y() - 0.2 * p.z()) / 1.1)),
                         static_cast<float>(128 + 90 * std::sin(tau * (p.z() + 0.4 * p.x()) / 0.7)));
}

// A camera at `center` looking at the origin, z up in the world.
TexturePhoto LookingAtOrigin(const std::string& name, const Eigen::Vector3d& center, double k1) {
  TexturePhoto photo;
  photo.name = name;
  photo.camera.width = 320;
  photo.camera.height = 240;
  photo.camera.focal = 300.0;
  photo.camera.cx = 159.5;
  photo.camera.cy = 119.5;
  photo.camera.k1 = k1;
  const Eigen::Vector3d forward = -center.normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  photo.cam_from_world.rotation.row(0) = right;
  photo.cam_from_world.rotation.row(1) = down;
  photo.cam_from_world.rotation.row(2) = forward;
  photo.cam_from_world.translation = -(photo.cam_from_world.rotation * center);
  return photo;
}

// Ray-cast photo of the mesh: TrueColour times `gain`, background grey; `blob` paints a red disc
// of that radius (pixels) at the image centre (a passer-by).
Image<uint8_t> RenderPhoto(const Mesh& mesh, const TriangleBvh& bvh, const TexturePhoto& photo, float gain,
                           double blob) {
  Image<uint8_t> image(photo.camera.width, photo.camera.height, 3);
  const Eigen::Matrix3d world_from_cam = photo.cam_from_world.rotation.transpose();
  const Eigen::Vector3d center = CameraCenterInWorld(photo.cam_from_world);
  for (int v = 0; v < image.height(); ++v) {
    for (int u = 0; u < image.width(); ++u) {
      Eigen::Vector3f colour(90, 90, 90);
      Eigen::Vector2d normalised;
      if (photo.camera.Undistort(Eigen::Vector2d(u, v), &normalised)) {
        const RayHit hit = bvh.Intersect(center, world_from_cam * normalised.homogeneous());
        if (hit.triangle >= 0) colour = gain * TrueColour(hit.point);
      }
      if (std::hypot(u - photo.camera.cx, v - photo.camera.cy) < blob) colour = Eigen::Vector3f(250, 20, 20);
      for (int c = 0; c < 3; ++c) image.row(v)[3 * u + c] = static_cast<uint8_t>(std::clamp(std::lround(colour[c]), 0L, 255L));
    }
  }
  (void)mesh;
  return image;
}

struct Scene {
  Mesh mesh;
  std::vector<TexturePhoto> photos;
  std::vector<Image<uint8_t>> images;
};

// Eight photos around the cube, two rings; photo 2 brighter by `gain`, photo 5 with a red blob.
Scene MakeScene(float gain, double blob, Mesh mesh = SubdividedCube(8)) {
  Scene scene;
  scene.mesh = std::move(mesh);
  const TriangleBvh bvh(scene.mesh);
  for (int k = 0; k < 8; ++k) {
    const double angle = 2.0 * M_PI * k / 8.0 + 0.3;
    const double height = k % 2 == 0 ? 1.6 : -1.5;
    const Eigen::Vector3d center(2.6 * std::cos(angle), 2.6 * std::sin(angle), height);
    scene.photos.push_back(LookingAtOrigin("photo" + std::to_string(k), center, k == 3 ? -0.08 : 0.0));
    scene.images.push_back(
        RenderPhoto(scene.mesh, bvh, scene.photos.back(), k == 2 ? gain : 1.0f, k == 5 ? blob : 0.0));
  }
  return scene;
}

PhotoLoader LoaderOf(const Scene& scene) {
  return [&scene](size_t i) -> Result<Image<uint8_t>> { return scene.images[i]; };
}

// Mean absolute difference (0..255, over channels) between the texture and the true colour at
// random points of the textured faces, and the largest.
void TextureError(const TexturedMesh& textured, double* mean, double* worst) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double sum = 0.0;
  *worst = 0.0;
  size_t count = 0;
  size_t page = 0;
  for (size_t triangle = 0; triangle < textured.mesh.triangles.size(); ++triangle) {
    while (triangle >= PageTrianglesEnd(textured.pages, page, textured.mesh.triangles.size())) ++page;
    const Image<uint8_t>& atlas = textured.pages[page].image;
    const auto& t = textured.mesh.triangles[triangle];
    if (!textured.mesh.colors.empty() && textured.mesh.colors[t[0]][0] != 255) continue;  // untextured
    for (int s = 0; s < 4; ++s) {
      double a = unit(random), b = unit(random);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      const double weights[3] = {1.0 - a - b, a, b};
      Eigen::Vector3d point = Eigen::Vector3d::Zero();
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) {
        point += weights[k] * textured.mesh.positions[t[k]].cast<double>();
        uv += weights[k] * textured.mesh.texcoords[t[k]].cast<double>();
      }
      float rgb[3];
      ASSERT_TRUE(SampleBilinear(atlas, uv.x() * atlas.width() - 0.5, uv.y() * atlas.height() - 0.5, rgb));
      const double error = (Eigen::Vector3f(rgb[0], rgb[1], rgb[2]) - TrueColour(point)).cwiseAbs().mean();
      sum += error;
      *worst = std::max(*worst, error);
      ++count;
    }
  }
  *mean = sum / static_cast<double>(count);
}

TEST(TextureMeshTest, GivesBackTheSurfaceColour) {
  const Scene scene = MakeScene(1.0f, 0.0);
  TextureOptions options;
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), options, &report);
  ASSERT_TRUE(textured.ok()) << textured.status().ToString();
  EXPECT_EQ(report.untextured_faces, 0u);
  EXPECT_EQ(report.textured_faces, scene.mesh.triangles.size());
  EXPECT_LE(report.labelling_energy_end, report.labelling_energy_start);
  EXPECT_GT(report.patches, 5u);
  EXPECT_LT(report.patches, 60u);
  ASSERT_TRUE(ValidateMesh(textured->mesh).ok());
  ASSERT_EQ(textured->mesh.texcoords.size(), textured->mesh.positions.size());
  double mean = 0.0, worst = 0.0;
  TextureError(*textured, &mean, &worst);
  // Resampling twice (render, then atlas) blurs the stripes a little; nothing else differs.
  EXPECT_LT(mean, 6.0);
  EXPECT_LT(worst, 60.0);
  EXPECT_EQ(report.texels_per_pixel, 1.0);
  EXPECT_EQ(report.atlas_pages, 1u);
  ASSERT_EQ(textured->pages.size(), 1u);
}

TEST(TextureMeshTest, ChartsThatOnePageCannotHoldGoOnMorePages) {
  const Scene scene = MakeScene(1.0f, 0.0);
  TextureOptions options;
  options.atlas_size = 256;
  options.max_pages = 16;
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), options, &report);
  ASSERT_TRUE(textured.ok()) << textured.status().ToString();
  EXPECT_GT(textured->pages.size(), 1u);
  EXPECT_EQ(report.atlas_pages, textured->pages.size());
  EXPECT_EQ(report.texels_per_pixel, 1.0);  // the photos' resolution kept
  ASSERT_TRUE(ValidateTexturePages(textured->pages, textured->mesh.triangles.size()).ok());
  for (const TexturePage& page : textured->pages) {
    EXPECT_LE(page.image.width(), 256);
    EXPECT_LE(page.image.height(), 256);
  }
  double mean = 0.0, worst = 0.0;
  TextureError(*textured, &mean, &worst);  // each triangle read from its own page
  EXPECT_LT(mean, 6.0);
  EXPECT_LT(worst, 60.0);
}

TEST(TextureMeshTest, LevelsABrighterPhotoAndIgnoresAPasserBy) {
  const Scene scene = MakeScene(1.35f, 40.0, Sphere(4));
  TextureOptions options;
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), options, &report);
  ASSERT_TRUE(textured.ok()) << textured.status().ToString();
  EXPECT_GT(report.inconsistent_candidates, 0u);
  EXPECT_LT(report.seam_step_after, 0.5 * report.seam_step_before);
  double mean = 0.0, worst = 0.0;
  TextureError(*textured, &mean, &worst);
  EXPECT_LT(mean, 15.0);

  // The brighter photo's gain: below the others' by most of 1 / 1.35 (its brightest stripes clip
  // at 255, which pulls its median ratio down); the others' near 1.35^(1/8), the mean kept.
  EXPECT_LT(report.min_gain, 0.9);
  EXPECT_GT(report.max_gain, 1.0);
  EXPECT_LT(report.max_gain, 1.1);
  options.check_photo_consistency = false;
  options.level_seams = false;
  options.level_exposure = false;
  TextureReport plain_report;
  const auto plain = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), options, &plain_report);
  ASSERT_TRUE(plain.ok());
  double plain_mean = 0.0, plain_worst = 0.0;
  TextureError(*plain, &plain_mean, &plain_worst);
  EXPECT_LT(mean, plain_mean);
  EXPECT_GT(plain_worst, 100.0);  // the red blob on the cube
  EXPECT_LT(worst, plain_worst);
}

TEST(TextureMeshTest, SmallAtlasLowersTheScale) {
  const Scene scene = MakeScene(1.0f, 0.0);
  TextureOptions options;
  options.atlas_size = 128;
  options.max_pages = 1;
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), options, &report);
  ASSERT_TRUE(textured.ok()) << textured.status().ToString();
  EXPECT_LT(report.texels_per_pixel, 1.0);
  ASSERT_EQ(textured->pages.size(), 1u);
  EXPECT_LE(textured->pages[0].image.width(), 128);
  EXPECT_LE(textured->pages[0].image.height(), 128);
}

TEST(TextureMeshTest, NoPhotoSeeingTheMeshIsAFailedPrecondition) {
  Scene scene = MakeScene(1.0f, 0.0);
  for (TexturePhoto& photo : scene.photos) {
    const Eigen::Vector3d center = CameraCenterInWorld(photo.cam_from_world);
    photo = LookingAtOrigin(photo.name, 2.0 * center, 0.0);  // then turned to look away
    photo.cam_from_world.rotation.row(0) *= -1.0;
    photo.cam_from_world.rotation.row(2) *= -1.0;
    photo.cam_from_world.translation = -(photo.cam_from_world.rotation * 2.0 * center);
  }
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, LoaderOf(scene), TextureOptions(), &report);
  ASSERT_FALSE(textured.ok());
  EXPECT_EQ(textured.status().code(), StatusCode::kFailedPrecondition);
}

TEST(TextureMeshTest, APhotoThatCannotBeLoadedIsNamed) {
  const Scene scene = MakeScene(1.0f, 0.0);
  const PhotoLoader failing = [&](size_t i) -> Result<Image<uint8_t>> {
    if (i == 4) return Status(StatusCode::kCorruptData, "photo4.jpg: truncated");
    return scene.images[i];
  };
  TextureReport report;
  const auto textured = TextureMesh(scene.mesh, scene.photos, failing, TextureOptions(), &report);
  ASSERT_FALSE(textured.ok());
  EXPECT_NE(textured.status().message().find("photo4.jpg"), std::string::npos);
}

}  // namespace
}  // namespace reconar
