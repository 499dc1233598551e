#include "core/sfm/model_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_model_io_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadText(const fs::path& path) {
  Result<std::string> text = ReadFileToString(path.string());
  EXPECT_TRUE(text.ok()) << text.status().ToString();
  return text.ok() ? *text : std::string();
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::vector<std::string> DataLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  }
  return lines;
}

SfmCamera Camera(int width, int height, const RadialCamera& model) {
  SfmCamera camera;
  static_cast<RadialCamera&>(camera) = model;
  camera.width = width;
  camera.height = height;
  return camera;
}

// Four images of 40 points, keypoints at the exact projections, plus one keypoint without a
// point per image. Image 2 is unregistered; point 5 is deleted; point 7 is seen only by image 2.
// The second camera has non-square pixels unless `second_aspect` says otherwise.
Reconstruction SyntheticScene(double second_aspect = 1.0017) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Reconstruction reconstruction;
  reconstruction.cameras.push_back(Camera(640, 480, {500.25, 319.5, 239.5, -0.05, 0.01}));
  reconstruction.cameras.push_back(Camera(800, 600, {610.125, 399.5, 299.5, 0.02, -0.003, second_aspect}));
  for (int p = 0; p < 40; ++p) {
    SfmPoint point;
    point.position = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    point.color = {static_cast<uint8_t>(p), static_cast<uint8_t>(200 - p), static_cast<uint8_t>(3 * p)};
    point.error = 0.1 + 0.01 * p;
    reconstruction.points.push_back(point);
  }
  for (int i = 0; i < 4; ++i) {
    SfmImage image;
    image.name = "image" + std::to_string(i) + ".jpg";
    image.camera_id = i % 2;
    image.registered = i != 2;
    const Eigen::Vector3d axis = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)).normalized();
    image.cam_from_world.rotation = Eigen::AngleAxisd(0.3 * uniform(rng), axis).toRotationMatrix();
    image.cam_from_world.translation = Eigen::Vector3d(0.5 * uniform(rng), 0.5 * uniform(rng), 6.0);
    const SfmCamera& camera = reconstruction.cameras[image.camera_id];
    for (int p = 0; p < 40; ++p) {
      if (p == 7 && i != 2) continue;
      image.keypoints.push_back(camera.Project(image.cam_from_world * (reconstruction.points[p].position)));
      image.point3d_ids.push_back(p);
      reconstruction.points[p].track.push_back({i, static_cast<int>(image.keypoints.size()) - 1});
    }
    image.keypoints.emplace_back(0.0, 0.0);
    image.point3d_ids.push_back(-1);
    reconstruction.images.push_back(image);
  }
  reconstruction.points[5].deleted = true;
  return reconstruction;
}

void ExpectSameCamera(const SfmCamera& a, const SfmCamera& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_DOUBLE_EQ(a.focal, b.focal);
  EXPECT_NEAR(a.cx, b.cx, 1e-12);
  EXPECT_NEAR(a.cy, b.cy, 1e-12);
  EXPECT_DOUBLE_EQ(a.k1, b.k1);
  EXPECT_DOUBLE_EQ(a.k2, b.k2);
  EXPECT_DOUBLE_EQ(a.aspect, b.aspect);
}

TEST(ModelIoTest, ColmapRoundTripIsExactWhenEverythingIsExported) {
  Reconstruction original = SyntheticScene();
  original.images[2].registered = true;
  original.points[5].deleted = false;
  const fs::path dir = TempDir("round_trip_all");
  ASSERT_TRUE(WriteColmapTextModel(original, dir.string()).ok());
  Result<Reconstruction> read = ReadColmapTextModel(dir.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();

  ASSERT_EQ(read->cameras.size(), original.cameras.size());
  for (size_t c = 0; c < original.cameras.size(); ++c) ExpectSameCamera(read->cameras[c], original.cameras[c]);
  ASSERT_EQ(read->images.size(), original.images.size());
  for (size_t i = 0; i < original.images.size(); ++i) {
    const SfmImage& a = read->images[i];
    const SfmImage& b = original.images[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera_id, b.camera_id);
    EXPECT_TRUE(a.registered);
    EXPECT_LT((a.cam_from_world.rotation - b.cam_from_world.rotation).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ(a.cam_from_world.translation, b.cam_from_world.translation);
    ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
    for (size_t k = 0; k < a.keypoints.size(); ++k) {
      EXPECT_LT((a.keypoints[k] - b.keypoints[k]).cwiseAbs().maxCoeff(), 1e-12);
    }
    EXPECT_EQ(a.point3d_ids, b.point3d_ids);
  }
  ASSERT_EQ(read->points.size(), original.points.size());
  for (size_t p = 0; p < original.points.size(); ++p) {
    const SfmPoint& a = read->points[p];
    const SfmPoint& b = original.points[p];
    EXPECT_EQ(a.position, b.position);
    EXPECT_EQ(a.color, b.color);
    EXPECT_EQ(a.error, b.error);
    ASSERT_EQ(a.track.size(), b.track.size());
    for (size_t e = 0; e < a.track.size(); ++e) {
      EXPECT_EQ(a.track[e].image_id, b.track[e].image_id);
      EXPECT_EQ(a.track[e].keypoint_id, b.track[e].keypoint_id);
    }
  }

  // Writing what was read gives the same files, except for quaternions that went through a
  // rotation matrix (equal to within 1e-15 above).
  const fs::path again = TempDir("round_trip_again");
  ASSERT_TRUE(WriteColmapTextModel(*read, again.string()).ok());
  for (const char* file : {"cameras.txt", "points3D.txt"}) {
    EXPECT_EQ(ReadText(again / file), ReadText(dir / file)) << file;
  }
}

TEST(ModelIoTest, ColmapWritesOnlyRegisteredImagesAndExportedPoints) {
  const Reconstruction original = SyntheticScene();
  const fs::path dir = TempDir("exported");
  ASSERT_TRUE(WriteColmapTextModel(original, dir.string()).ok());

  // Image 2 (IMAGE_ID 3) is unregistered: absent from images.txt and from every track.
  const std::vector<std::string> images = DataLines(ReadText(dir / "images.txt"));
  ASSERT_EQ(images.size(), 6u);
  for (size_t i = 0; i < images.size(); i += 2) EXPECT_EQ(images[i].find("image2.jpg"), std::string::npos);
  const std::vector<std::string> points = DataLines(ReadText(dir / "points3D.txt"));
  EXPECT_EQ(points.size(), 38u);  // 40 minus deleted point 5 and point 7 seen only by image 2
  for (const std::string& line : points) {
    std::istringstream in(line);
    int id;
    double value;
    in >> id;
    EXPECT_NE(id, 6);  // point 5
    EXPECT_NE(id, 8);  // point 7
    for (int i = 0; i < 7; ++i) in >> value;
    for (int image_id, keypoint; in >> image_id >> keypoint;) EXPECT_NE(image_id, 3) << line;
  }
  // Keypoints of the deleted point read back without a point.
  Result<Reconstruction> read = ReadColmapTextModel(dir.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->images.size(), 3u);
  EXPECT_EQ(read->images[2].name, "image3.jpg");
  EXPECT_EQ(read->images[0].point3d_ids[5], -1);
  EXPECT_EQ(read->points.size(), 38u);
  EXPECT_EQ(read->points[5].position, original.points[6].position);
  for (const SfmPoint& point : read->points) EXPECT_EQ(point.track.size(), 3u);
}

TEST(ModelIoTest, ColmapHeadersAndPixelConvention) {
  Reconstruction model;
  model.cameras.push_back(Camera(640, 480, {500.0, 319.5, 239.5}));
  SfmImage image;
  image.name = "a.png";
  image.camera_id = 0;
  image.registered = true;
  image.keypoints = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(10.25, 20.0)};
  image.point3d_ids = {0, -1};
  model.images.push_back(image);
  SfmPoint point;
  point.position = Eigen::Vector3d(0.5, -1.0, 2.0);
  point.color = {1, 2, 3};
  point.error = 0.25;
  point.track = {{0, 0}};
  model.points.push_back(point);

  const fs::path dir = TempDir("headers");
  ASSERT_TRUE(WriteColmapTextModel(model, dir.string()).ok());
  EXPECT_EQ(ReadText(dir / "cameras.txt"),
            "# Camera list with one line of data per camera:\n"
            "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
            "# Number of cameras: 1\n"
            "1 RADIAL 640 480 500 320 240 0 0\n");
  EXPECT_EQ(ReadText(dir / "images.txt"),
            "# Image list with two lines of data per image:\n"
            "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
            "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
            "# Number of images: 1, mean observations per image: 1\n"
            "1 1 0 0 0 0 0 0 1 a.png\n"
            "0.5 0.5 1 10.75 20.5 -1\n");
  EXPECT_EQ(ReadText(dir / "points3D.txt"),
            "# 3D point list with one line of data per point:\n"
            "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
            "# Number of points: 1, mean track length: 1\n"
            "1 0.5 -1 2 1 2 3 0.25 1 0\n");
}

TEST(ModelIoTest, ReadsOtherColmapCameraModels) {
  const fs::path dir = TempDir("models");
  WriteText(dir / "cameras.txt",
            "# comment\n"
            "\n"
            "7 SIMPLE_PINHOLE 100 80 90 50 40\n"
            "3 PINHOLE 100 80 95 95.00000001 50.5 40.5\n"
            "5 SIMPLE_RADIAL 100 80 99 50 40 -0.1\n");
  WriteText(dir / "images.txt", "2 1 0 0 0 0 0 1 5 x.jpg\n\n1 1 0 0 0 0 0 1 7 y.jpg\n1.5 2.5 -1\n");
  WriteText(dir / "points3D.txt", "");
  Result<Reconstruction> read = ReadColmapTextModel(dir.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->cameras.size(), 3u);
  // Sorted by id: 3 PINHOLE, 5 SIMPLE_RADIAL, 7 SIMPLE_PINHOLE.
  EXPECT_EQ(read->cameras[0].focal, 95.0);
  EXPECT_NEAR(read->cameras[0].aspect, 1.0 + 1e-8 / 95.0, 1e-15);
  EXPECT_EQ(read->cameras[0].cx, 50.0);
  EXPECT_EQ(read->cameras[1].k1, -0.1);
  EXPECT_EQ(read->cameras[1].k2, 0.0);
  EXPECT_EQ(read->cameras[2].focal, 90.0);
  EXPECT_EQ(read->cameras[2].cy, 39.5);
  ASSERT_EQ(read->images.size(), 2u);
  EXPECT_EQ(read->images[0].name, "y.jpg");  // IMAGE_ID 1
  EXPECT_EQ(read->images[0].camera_id, 2);
  EXPECT_EQ(read->images[0].keypoints[0], Eigen::Vector2d(1.0, 2.0));
  EXPECT_TRUE(read->images[1].keypoints.empty());  // empty POINTS2D line
  EXPECT_EQ(read->images[1].camera_id, 1);
}

// Writes a valid one-point model, replaces one file's content, and expects the error to name it.
struct MalformedCase {
  const char* file;
  const char* content;
  const char* place;  // expected "file:line" inside the message
  const char* reason;
};

TEST(ModelIoTest, MalformedInputErrorsNameFileAndLine) {
  const MalformedCase cases[] = {
      {"cameras.txt", "# c\n1 OPENCV 100 80 90 91 50 40 0 0 0.001 0\n", "cameras.txt:2:", "tangential"},
      {"cameras.txt", "1 FULL_OPENCV 100 80 90 91 50 40 0 0 0 0 0 0 0 0\n", "cameras.txt:1:", "not supported"},
      {"cameras.txt", "1 RADIAL 100 80 90 50 40 0\n", "cameras.txt:1:", "needs 5 parameters"},
      {"cameras.txt", "1 RADIAL 100 80 90 50 4o 0 0\n", "cameras.txt:1:", "bad camera parameter '4o'"},
      {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n", "images.txt:1:", "missing POINTS2D"},
      {"images.txt", "# x\n1 1 0 0 0 0 0 0 1 a.png\n0.5 0.5\n", "images.txt:3:", "triples"},
      {"images.txt", "1 1 0 0 0 0 0 0 1\n0.5 0.5 1\n", "images.txt:1:", "expected IMAGE_ID"},
      {"images.txt", "1 1 0 0 0 0 0 0 4 a.png\n0.5 0.5 1\n", "images.txt:1:", "CAMERA_ID 4 not in cameras.txt"},
      {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n0.5 0.5 9\n", "images.txt:2:", "POINT3D_ID 9 not in points3D.txt"},
      {"images.txt", "1 0 0 0 0 0 0 0 1 a.png\n0.5 0.5 1\n", "images.txt:1:", "quaternion"},
      {"points3D.txt", "\n\n1 0 0 1 1 2 3 0.5 1\n", "points3D.txt:3:", "expected POINT3D_ID"},
      {"points3D.txt", "1 0 0 1 1 2 300 0.5 1 0\n", "points3D.txt:1:", "colour"},
      {"points3D.txt", "1 0 0 1 1 2 3 0.5 2 0\n", "points3D.txt:1:", "IMAGE_ID not in images.txt"},
      {"points3D.txt", "1 0 0 1 1 2 3 0.5 1 4\n", "points3D.txt:1:", "POINT2D_IDX out of range"},
      {"points3D.txt", "1 0 0 1 1 2 3 0.5 1 0\n1 0 0 1 1 2 3 0.5\n", "points3D.txt:2:", "duplicate POINT3D_ID"},
  };
  const char* valid[][2] = {{"cameras.txt", "1 RADIAL 100 80 90 50 40 0 0\n"},
                            {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n0.5 0.5 1\n"},
                            {"points3D.txt", "1 0 0 1 1 2 3 0.5 1 0\n"}};
  for (const MalformedCase& c : cases) {
    const fs::path dir = TempDir("malformed");
    for (const auto& file : valid) WriteText(dir / file[0], file[1]);
    ASSERT_TRUE(ReadColmapTextModel(dir.string()).ok());
    WriteText(dir / c.file, c.content);
    Result<Reconstruction> read = ReadColmapTextModel(dir.string());
    ASSERT_FALSE(read.ok()) << c.file << ": " << c.content;
    EXPECT_EQ(read.status().code(), StatusCode::kCorruptData);
    const std::string& message = read.status().message();
    EXPECT_NE(message.find((dir / c.place).string()), std::string::npos) << message;
    EXPECT_NE(message.find(c.reason), std::string::npos) << message;
  }

  const fs::path dir = TempDir("missing");
  Result<Reconstruction> read = ReadColmapTextModel(dir.string());
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kNotFound);
  EXPECT_NE(read.status().message().find((dir / "cameras.txt").string()), std::string::npos);
}

// Bundler's projection (bundler/README): P = R X + t, p = -P.xy / P.z, p' = f r(p) p with
// r(p) = 1 + k1 |p|^2 + k2 |p|^4, in pixels from the image centre with y up.
TEST(ModelIoTest, BundlerProjectionMatchesSfmCamera) {
  const Reconstruction model = SyntheticScene(/*second_aspect=*/1.0);  // Bundler has square pixels
  const fs::path dir = TempDir("bundler");
  const std::vector<std::string> paths = {"p/0.jpg", "p/1.jpg", "p/2.jpg", "p/3.jpg"};
  ASSERT_TRUE(WriteBundlerModel(model, (dir / "bundle.out").string(), (dir / "list.txt").string(), paths).ok());
  EXPECT_EQ(ReadText(dir / "list.txt"), "p/0.jpg\np/1.jpg\np/2.jpg\np/3.jpg\n");

  std::istringstream in(ReadText(dir / "bundle.out"));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "# Bundle file v0.3");
  int num_cameras = 0;
  int num_points = 0;
  in >> num_cameras >> num_points;
  ASSERT_EQ(num_cameras, 4);
  ASSERT_EQ(num_points, 38);
  struct BundlerCamera {
    double f, k1, k2;
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
  };
  std::vector<BundlerCamera> cameras(num_cameras);
  for (BundlerCamera& c : cameras) {
    in >> c.f >> c.k1 >> c.k2;
    for (int r = 0; r < 3; ++r) in >> c.R(r, 0) >> c.R(r, 1) >> c.R(r, 2);
    in >> c.t.x() >> c.t.y() >> c.t.z();
  }
  EXPECT_EQ(cameras[2].f, 0.0);
  EXPECT_EQ(cameras[2].R, Eigen::Matrix3d::Zero());
  EXPECT_EQ(cameras[2].t, Eigen::Vector3d::Zero());

  int num_checked = 0;
  for (int p = 0; p < num_points; ++p) {
    Eigen::Vector3d X;
    int r, g, b, num_views;
    in >> X.x() >> X.y() >> X.z() >> r >> g >> b >> num_views;
    ASSERT_TRUE(in) << "point " << p;
    EXPECT_EQ(num_views, 3);
    for (int v = 0; v < num_views; ++v) {
      int camera_index, key;
      Eigen::Vector2d xy;
      in >> camera_index >> key >> xy.x() >> xy.y();
      ASSERT_NE(camera_index, 2);
      const BundlerCamera& c = cameras[camera_index];
      const Eigen::Vector3d P = c.R * X + c.t;
      const Eigen::Vector2d q = -P.head<2>() / P.z();
      const Eigen::Vector2d projected = c.f * (1 + c.k1 * q.squaredNorm() + c.k2 * q.squaredNorm() * q.squaredNorm()) * q;

      const SfmImage& image = model.images[camera_index];
      const SfmCamera& camera = model.cameras[image.camera_id];
      const Eigen::Vector2d pixel = camera.Project(image.cam_from_world * X);
      const Eigen::Vector2d from_bundler(projected.x() + 0.5 * (camera.width - 1),
                                         0.5 * (camera.height - 1) - projected.y());
      EXPECT_LT((from_bundler - pixel).norm(), 1e-9);
      EXPECT_LT((xy - projected).norm(), 1e-9);  // keypoints are the exact projections
      EXPECT_EQ(image.keypoints[key], pixel);
      ++num_checked;
    }
  }
  EXPECT_EQ(num_checked, 38 * 3);

  EXPECT_FALSE(WriteBundlerModel(model, (dir / "b.out").string(), (dir / "l.txt").string(), {"one"}).ok());
}

TEST(ModelIoTest, PlyIsBinaryLittleEndianWithColours) {
  const Reconstruction model = SyntheticScene();
  const fs::path path = TempDir("ply") / "sparse.ply";
  ASSERT_TRUE(WritePointsPly(model, path.string()).ok());
  const std::string content = ReadText(path);
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 38\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  ASSERT_EQ(content.substr(0, header.size()), header);
  ASSERT_EQ(content.size(), header.size() + 38 * 15);
  const unsigned char* vertex = reinterpret_cast<const unsigned char*>(content.data()) + header.size();
  const SfmPoint& first = model.points[0];
  for (int axis = 0; axis < 3; ++axis) {
    const uint32_t bits = vertex[4 * axis] | vertex[4 * axis + 1] << 8 | vertex[4 * axis + 2] << 16 |
                          static_cast<uint32_t>(vertex[4 * axis + 3]) << 24;
    float value;
    std::memcpy(&value, &bits, sizeof(value));
    EXPECT_EQ(value, static_cast<float>(first.position[axis]));
  }
  EXPECT_EQ(vertex[12], first.color[0]);
  EXPECT_EQ(vertex[13], first.color[1]);
  EXPECT_EQ(vertex[14], first.color[2]);
}

TEST(ModelIoTest, WriteIntoReadOnlyDirectoryFails) {
  const fs::path dir = TempDir("read_only");
  ASSERT_EQ(::chmod(dir.c_str(), 0555), 0);
  if (::access(dir.c_str(), W_OK) == 0) {
    ::chmod(dir.c_str(), 0755);
    GTEST_SKIP() << "running with permission to write anyway (root)";
  }
  const Status status = WriteColmapTextModel(SyntheticScene(), dir.string());
  ::chmod(dir.c_str(), 0755);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find((dir / "cameras.txt").string()), std::string::npos) << status.message();
  EXPECT_TRUE(fs::is_empty(dir));
}

// Works as root too: a directory where a file should go makes the rename fail, and neither
// that path nor a temporary is left behind.
TEST(ModelIoTest, FailedWriteLeavesNoPartialFile) {
  const fs::path dir = TempDir("blocked");
  fs::create_directory(dir / "points3D.txt");
  const Status status = WriteColmapTextModel(SyntheticScene(), dir.string());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find((dir / "points3D.txt").string()), std::string::npos) << status.message();
  EXPECT_TRUE(fs::is_directory(dir / "points3D.txt"));
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }

  const fs::path under_file = dir / "cameras.txt" / "model";
  EXPECT_FALSE(WriteColmapTextModel(SyntheticScene(), under_file.string()).ok());
}

TEST(ModelIoTest, InconsistentModelIsRejected) {
  Reconstruction model = SyntheticScene();
  model.images[0].point3d_ids[3] = 99;
  const Status status = WriteColmapTextModel(model, TempDir("inconsistent").string());
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("point3d_id 99"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace reconar
