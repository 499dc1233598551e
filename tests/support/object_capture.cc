#include "tests/support/object_capture.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/prng.h"
#include "core/base/thread_pool.h"
#include "core/io/image_write.h"
#include "core/math/rigid3.h"
#include "tests/support/mesh_raster.h"
#include "tests/support/numbered_name.h"
#include "tests/support/supersampling.h"

namespace reconar::testing {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Lambert's light: the direction towards it (from above, the front and the side), fixed in the world.
const Eigen::Vector3d kTowardsLight = Eigen::Vector3d(0.3, 1.0, 0.5).normalized();
// The clay's tint: per channel, times the grey level.
const Eigen::Vector3f kClayTint(1.0f, 0.92f, 0.82f);

// A value in [0, 1) for each point of the integer lattice (and each seed).
double LatticeValue(const int64_t* point, int dims, uint64_t seed) {
  static constexpr uint64_t kPrimes[3] = {0x9E3779B97F4A7C15ull, 0xC2B2AE3D27D4EB4Full, 0x165667B19E3779F9ull};
  uint64_t key = seed;
  for (int d = 0; d < dims; ++d) key ^= static_cast<uint64_t>(point[d]) * kPrimes[d];
  return SplitMix64(key).Uniform01();
}

// Value noise in [0, 1) on the unit lattice of kDims dimensions: the lattice's values interpolated
// with smoothstep weights.
template <int kDims>
double ValueNoise(const Eigen::Matrix<double, kDims, 1>& p, uint64_t seed) {
  int64_t cell[kDims];
  double weight[kDims];
  for (int d = 0; d < kDims; ++d) {
    const double floor = std::floor(p[d]), f = p[d] - floor;
    cell[d] = static_cast<int64_t>(floor);
    weight[d] = f * f * (3.0 - 2.0 * f);
  }
  double value = 0.0;
  for (int corner = 0; corner < (1 << kDims); ++corner) {
    int64_t point[kDims];
    double corner_weight = 1.0;
    for (int d = 0; d < kDims; ++d) {
      const int step = (corner >> d) & 1;
      point[d] = cell[d] + step;
      corner_weight *= step ? weight[d] : 1.0 - weight[d];
    }
    value += corner_weight * LatticeValue(point, kDims, seed);
  }
  return value;
}

// Three octaves of value noise from `cell` (weights 0.5, 0.3, 0.2 from the finest), scaled to a
// standard deviation of 1: the sum's own is 0.228 in 3D and 0.267 in 2D (measured over 2e6 random
// points), well below its range of +-1; scaled, it stays within +-4.
template <int kDims>
double Octaves(const Eigen::Matrix<double, kDims, 1>& p, double cell, uint64_t seed) {
  static_assert(kDims == 2 || kDims == 3, "the scale is measured for 2 and 3 dimensions");
  const double weights[3] = {0.5, 0.3, 0.2};
  double sum = 0.0;
  for (int octave = 0; octave < 3; ++octave) {
    const Eigen::Matrix<double, kDims, 1> scaled = p / (cell * (1 << octave));
    sum += weights[octave] * (2.0 * ValueNoise<kDims>(scaled, seed + static_cast<uint64_t>(octave)) - 1.0);
  }
  return sum / (kDims == 3 ? 0.228 : 0.267);
}

}  // namespace

Status ObjectCaptureOptions::Check() const {
  const auto fail = [](const std::string& what) { return InvalidArgument("ObjectCaptureOptions: " + what); };
  if (views < 1) return fail("views must be at least 1");
  if (!(revolutions >= 0.0)) return fail("revolutions must be >= 0");
  if (!(min_elevation_deg >= -89.0 && max_elevation_deg <= 89.0 && min_elevation_deg <= max_elevation_deg)) {
    return fail("elevations must satisfy -89 <= min <= max <= 89 degrees");
  }
  if (!(distance_m > 0.0)) return fail("distance_m must be positive");
  if (width < 8 || height < 8) return fail("width and height must be at least 8");
  if (!(focal_px > 0.0)) return fail("focal_px must be positive");
  if (!(position_jitter_deg >= 0.0 && aim_jitter_deg >= 0.0 && roll_jitter_deg >= 0.0)) {
    return fail("jitters must be >= 0");
  }
  if (!(distance_jitter >= 0.0 && distance_jitter < 0.5)) return fail("distance_jitter must be in [0, 0.5)");
  if (!(texture_cell_m > 0.0)) return fail("texture_cell_m must be positive");
  if (!(ambient >= 0.0 && ambient <= 1.0)) return fail("ambient must be in [0, 1]");
  if (!(noise_sigma >= 0.0)) return fail("noise_sigma must be >= 0");
  if (supersampling < 1 || supersampling > 4) return fail("supersampling must be 1..4");
  return Status::Ok();
}

Eigen::Vector3d BoundingBoxCenter(const Mesh& mesh) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY);
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-INFINITY);
  for (const Eigen::Vector3f& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (0.5 * (lo + hi)).cast<double>();
}

std::vector<NamedGroundTruthCamera> ObjectCaptureCameras(const ObjectCaptureOptions& options,
                                                         const Eigen::Vector3d& centre) {
  SplitMix64 random(options.seed);
  const auto jitter = [&random](double amplitude) { return random.Uniform(-amplitude, amplitude); };
  std::vector<NamedGroundTruthCamera> views;
  for (int i = 0; i < options.views; ++i) {
    const double along = options.views > 1 ? static_cast<double>(i) / (options.views - 1) : 0.0;
    const double elevation =
        (options.min_elevation_deg + along * (options.max_elevation_deg - options.min_elevation_deg) +
         jitter(options.position_jitter_deg)) *
        kDegree;
    const double azimuth =
        (360.0 * options.revolutions * i / options.views + jitter(options.position_jitter_deg)) * kDegree;
    const double distance = options.distance_m * (1.0 + jitter(options.distance_jitter));
    const Eigen::Vector3d eye =
        centre + distance * Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                                            std::cos(elevation) * std::cos(azimuth));
    const Rigid3 looking = CamFromWorldLookingAt(eye, centre, Eigen::Vector3d::UnitY());
    // The hand's aim and roll, about the camera's own axes.
    const Eigen::Matrix3d hand =
        (Eigen::AngleAxisd(jitter(options.roll_jitter_deg) * kDegree, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(jitter(options.aim_jitter_deg) * kDegree, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(jitter(options.aim_jitter_deg) * kDegree, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    NamedGroundTruthCamera view;
    view.name = NumberedName("view_", i, options.views, 3, ".png");
    GroundTruthCamera& camera = view.camera;
    camera.width = options.width;
    camera.height = options.height;
    camera.K << options.focal_px, 0.0, 0.5 * (options.width - 1), 0.0, options.focal_px, 0.5 * (options.height - 1),
        0.0, 0.0, 1.0;
    camera.cam_from_world_rotation = hand * looking.rotation;
    camera.cam_from_world_translation = -camera.cam_from_world_rotation * eye;
    views.push_back(std::move(view));
  }
  return views;
}

Result<ObjectCaptureScene> ObjectCaptureScene::Create(Mesh object, const ObjectCaptureOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(ValidateMesh(object).WithContext("ObjectCaptureScene"));
  if (object.triangles.empty()) return InvalidArgument("ObjectCaptureScene: the mesh has no triangles");
  ObjectCaptureScene scene;
  if (object.normals.empty()) ComputeVertexNormals(&object);
  scene.object_ = std::move(object);
  scene.options_ = options;
  scene.centre_ = BoundingBoxCenter(scene.object_);
  scene.floor_y_ = INFINITY;
  for (const Eigen::Vector3f& p : scene.object_.positions)
    scene.floor_y_ = std::min(scene.floor_y_, static_cast<double>(p.y()));
  scene.views_ = ObjectCaptureCameras(options, scene.centre_);
  for (const NamedGroundTruthCamera& view : scene.views_) {
    if (!(view.camera.Centre().y() > scene.floor_y_)) {
      return InvalidArgument("ObjectCaptureScene: " + view.name + "'s camera is not above the floor");
    }
  }
  return scene;
}

Eigen::Vector3f ObjectCaptureScene::Colour(const GroundTruthCamera& camera, const Eigen::Vector3d& direction,
                                           int32_t triangle) const {
  const Eigen::Vector3d eye = camera.Centre();
  const uint64_t seed = options_.seed;
  if (triangle < 0) {
    if (direction.y() >= 0.0) return Eigen::Vector3f::Constant(static_cast<float>(options_.background_level));
    const Eigen::Vector3d floor = eye + (floor_y_ - eye.y()) / direction.y() * direction;
    const double level =
        options_.background_level +
        options_.background_contrast * Octaves<2>(Eigen::Vector2d(floor.x(), floor.z()), 0.01, seed + 16);
    return Eigen::Vector3f::Constant(static_cast<float>(level));
  }
  const auto& corners = object_.triangles[static_cast<size_t>(triangle)];
  const Eigen::Vector3d a = object_.positions[corners[0]].cast<double>(),
                        b = object_.positions[corners[1]].cast<double>(),
                        c = object_.positions[corners[2]].cast<double>();
  // The ray's point on the triangle's plane, and its barycentric weights there.
  const Eigen::Vector3d face = (b - a).cross(c - a);
  const double rate = face.dot(direction);
  const Eigen::Vector3d p = std::abs(rate) > 0.0 ? Eigen::Vector3d(eye + face.dot(a - eye) / rate * direction) : a;
  const double area = face.squaredNorm();
  const double wa = (b - p).cross(c - p).dot(face) / area, wb = (c - p).cross(a - p).dot(face) / area;
  Eigen::Vector3d normal =
      (wa * object_.normals[corners[0]].cast<double>() + wb * object_.normals[corners[1]].cast<double>() +
       (1.0 - wa - wb) * object_.normals[corners[2]].cast<double>());
  if (normal.squaredNorm() < 1e-24) normal = face;
  normal.normalize();
  if (normal.dot(direction) > 0.0) normal = -normal;  // the side the camera sees
  const double shade = options_.ambient + (1.0 - options_.ambient) * std::max(0.0, normal.dot(kTowardsLight));
  const double level =
      options_.surface_level + options_.texture_contrast * Octaves<3>(p, options_.texture_cell_m, seed);
  return kClayTint * static_cast<float>(level * shade);
}

Image<uint8_t> ObjectCaptureScene::Render(size_t index) const {
  const GroundTruthCamera& camera = views_[index].camera;
  const int s = options_.supersampling;
  // The fine grid as a camera of its own: fine pixel X at FineSampleCoordinate(X) of the view.
  PinholeView fine_view;
  fine_view.fx = s * camera.K(0, 0);
  fine_view.fy = s * camera.K(1, 1);
  fine_view.cx = s * camera.K(0, 2) + 0.5 * (s - 1);
  fine_view.cy = s * camera.K(1, 2) + 0.5 * (s - 1);
  fine_view.width = s * camera.width;
  fine_view.height = s * camera.height;
  fine_view.cam_from_world.rotation = camera.cam_from_world_rotation;
  fine_view.cam_from_world.translation = camera.cam_from_world_translation;
  const TriangleRaster raster = RasterizeTriangles(object_, fine_view);
  const Eigen::Matrix3d world_from_cam = camera.cam_from_world_rotation.transpose();
  Image<float> fine(fine_view.width, fine_view.height, 3);
  for (int y = 0; y < fine.height(); ++y) {
    float* row = fine.row(y);
    const double py = FineSampleCoordinate(y, s);
    for (int x = 0; x < fine.width(); ++x) {
      const double px = FineSampleCoordinate(x, s);
      const Eigen::Vector3d direction = world_from_cam * Eigen::Vector3d((px - camera.K(0, 2)) / camera.K(0, 0),
                                                                         (py - camera.K(1, 2)) / camera.K(1, 1), 1.0);
      const Eigen::Vector3f colour = Colour(camera, direction, raster.triangle.row(y)[x]);
      std::copy(colour.data(), colour.data() + 3, row + 3 * x);
    }
  }
  Image<float> picture = AverageSamples(fine, s);
  SplitMix64 noise(options_.seed * 0x9E3779B97F4A7C15ull + index + 1);
  float* samples = picture.data();
  for (size_t i = 0; i < picture.size_bytes() / sizeof(float); ++i) {
    samples[i] += static_cast<float>(options_.noise_sigma * noise.Gaussian());
  }
  return ToBytes(picture);
}

Result<GroundTruthByName> WriteObjectCapture(const ObjectCaptureScene& scene, const std::string& out_dir) {
  const std::vector<NamedGroundTruthCamera>& views = scene.views();
  std::vector<Status> written(views.size());
  ThreadPool pool(scene.options().threads);
  pool.ParallelFor(0, views.size(), [&](size_t i, int) {
    const Image<uint8_t> picture = scene.Render(i);
    written[i] = WritePng(out_dir + "/" + views[i].name, picture.view(), 3);
  });
  GroundTruthByName truth;
  for (size_t i = 0; i < views.size(); ++i) {
    if (!written[i].ok()) return written[i];
    truth[views[i].name] = views[i].camera;
  }
  return truth;
}

}  // namespace reconar::testing
