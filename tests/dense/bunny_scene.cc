#include "tests/dense/bunny_scene.h"

#include <GLES3/gl3.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "core/math/rigid3.h"
#include "core/base/atomic_file.h"
#include "core/io/image_write.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "render/camera_projection.h"
#include "render/gl_error.h"
#include "render/gl_handles.h"
#include "render/offscreen_target.h"
#include "render/shader_program.h"

namespace reconar {
namespace testing {
namespace {

constexpr double kDepthEncodingRangeM = 2.0;  // RenderDepth's 24-bit fixed point spans [0, 2 m)
constexpr int kDepthEncodingSteps = (1 << 24) - 1;

enum AttributeLocation : GLuint { kPosition = 0, kNormal = 1 };

constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_clip_from_world;
uniform mat4 u_cam_from_world;
out vec3 v_world_position;
out vec3 v_world_normal;
out float v_cam_depth;
void main() {
  v_world_position = a_position;
  v_world_normal = a_normal;
  v_cam_depth = (u_cam_from_world * vec4(a_position, 1.0)).z;
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
)";

// u_mode 0: texture and shading; 1: camera depth as 24-bit fixed point in RGB.
// Value noise: trilinear (smoothstep) interpolation of a hash on the integer lattice (the hash is
// Inigo Quilez's, exact in highp float for the lattice coordinates used here, |x| < 1000).
constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
precision highp int;
uniform int u_mode;
uniform float u_inverse_cell;
uniform vec3 u_light_direction;
in vec3 v_world_position;
in vec3 v_world_normal;
in float v_cam_depth;
out vec4 o_color;

float Hash(vec3 p) {
  p = fract(p * 0.3183099 + 0.1);
  p *= 17.0;
  return fract(p.x * p.y * p.z * (p.x + p.y + p.z));
}

float ValueNoise(vec3 x) {
  vec3 i = floor(x);
  vec3 f = fract(x);
  f = f * f * (3.0 - 2.0 * f);
  float n000 = Hash(i), n100 = Hash(i + vec3(1, 0, 0)), n010 = Hash(i + vec3(0, 1, 0)), n110 = Hash(i + vec3(1, 1, 0));
  float n001 = Hash(i + vec3(0, 0, 1)), n101 = Hash(i + vec3(1, 0, 1)), n011 = Hash(i + vec3(0, 1, 1));
  float n111 = Hash(i + vec3(1, 1, 1));
  return mix(mix(mix(n000, n100, f.x), mix(n010, n110, f.x), f.y),
             mix(mix(n001, n101, f.x), mix(n011, n111, f.x), f.y), f.z);
}

void main() {
  if (u_mode == 1) {
    uint q = uint(clamp(v_cam_depth / 2.0, 0.0, 1.0) * 16777215.0 + 0.5);
    o_color = vec4(float(q >> 16u), float((q >> 8u) & 255u), float(q & 255u), 255.0) / 255.0;
    return;
  }
  vec3 p = v_world_position * u_inverse_cell;
  float fine = 0.5 * ValueNoise(p) + 0.3 * ValueNoise(0.5 * p + 17.0) + 0.2 * ValueNoise(0.25 * p + 41.0);
  float albedo = mix(0.12, 1.0, smoothstep(0.35, 0.65, fine));
  float tint = ValueNoise(0.0625 * p + 73.0);
  vec3 colour = albedo * mix(vec3(1.0, 0.82, 0.66), vec3(0.70, 0.86, 1.0), tint);
  vec3 n = normalize(v_world_normal);
  float shade = 0.35 + 0.65 * max(dot(n, u_light_direction), 0.0);
  o_color = vec4(colour * shade, 1.0);
}
)";

void ToGl(const Eigen::Matrix4d& m, float out[16]) {
  const Eigen::Matrix4f f = m.cast<float>();
  std::copy(f.data(), f.data() + 16, out);  // column major, as GL wants
}

Eigen::Matrix4d CamFromWorld(const Rigid3& pose) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = pose.rotation;
  m.topRightCorner<3, 1>() = pose.translation;
  return m;
}

// A camera at `center` looking at `target`, image y pointing down the world's -y (world y is up).
Rigid3 LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  const Rigid3 cam_from_world = CamFromWorldLookingAt(center, target, Eigen::Vector3d::UnitY());
  Rigid3 pose;
  pose.rotation = cam_from_world.rotation;
  pose.translation = cam_from_world.translation;
  return pose;
}

std::string ViewName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "bunny_%03d.png", index);
  return name;
}

}  // namespace

Status BunnySceneOptions::Check() const {
  auto fail = [](const std::string& what) { return InvalidArgument("BunnySceneOptions: " + what); };
  if (width <= 0 || height <= 0) return fail("width and height must be positive");
  if (!(focal_px > 0.0)) return fail("focal_px must be positive");
  if (!(distance_m > 0.0 && distance_m < 0.5 * kDepthEncodingRangeM)) return fail("distance_m must be in (0, 1) m");
  if (cameras_per_ring < 1) return fail("cameras_per_ring must be at least 1");
  if (!(std::abs(low_ring_elevation_deg) < 89.0 && std::abs(high_ring_elevation_deg) < 89.0)) {
    return fail("ring elevations must be within (-89, 89) degrees");
  }
  if (supersampling < 1 || supersampling > 4) return fail("supersampling must be 1..4");
  if (!(texture_cell_m > 0.0)) return fail("texture_cell_m must be positive");
  return Status::Ok();
}

Reconstruction MakeBunnyCameras(const Mesh& bunny, const BunnySceneOptions& options) {
  Reconstruction model;
  SfmCamera camera;
  camera.width = options.width;
  camera.height = options.height;
  camera.focal = options.focal_px;
  camera.cx = 0.5 * (options.width - 1);
  camera.cy = 0.5 * (options.height - 1);
  model.cameras.push_back(camera);

  const Eigen::Vector3d target = BoundingBoxCenter(bunny);
  const double step = 2.0 * M_PI / options.cameras_per_ring;
  const double elevations[2] = {options.low_ring_elevation_deg * M_PI / 180.0,
                                options.high_ring_elevation_deg * M_PI / 180.0};
  for (int ring = 0; ring < 2; ++ring) {
    for (int k = 0; k < options.cameras_per_ring; ++k) {
      const double azimuth = step * (k + 0.5 * ring);
      const double elevation = elevations[ring];
      const Eigen::Vector3d direction(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                                      std::cos(elevation) * std::cos(azimuth));
      SfmImage image;
      image.name = ViewName(static_cast<int>(model.images.size()));
      image.camera_id = 0;
      image.registered = true;
      image.cam_from_world = LookAt(target + options.distance_m * direction, target);
      model.images.push_back(std::move(image));
    }
  }
  return model;
}

struct BunnyRenderer::Gl {
  BunnySceneOptions options;
  ShaderProgram program;
  GLint clip_from_world = -1;
  GLint cam_from_world = -1;
  GLint mode = -1;
  GLint inverse_cell = -1;
  GLint light_direction = -1;
  GlVertexArray vertex_array;
  GlBuffer positions;
  GlBuffer normals;
  GlBuffer indices;
  GLsizei index_count = 0;
  OffscreenTarget color_target;  // supersampling * (width x height)
  OffscreenTarget depth_target;  // width x height
  Image<uint8_t> readback;

  Status Draw(const SfmCamera& camera, const Rigid3& pose, OffscreenTarget* target, int mode_value) {
    const CameraIntrinsics intrinsics = IntrinsicsForTarget(camera.Intrinsics(), target->width(), target->height());
    DepthRange depth;
    depth.near_m = 0.02;
    depth.far_m = kDepthEncodingRangeM;
    float clip_from_world_gl[16];
    float cam_from_world_gl[16];
    const Eigen::Matrix4d cam_from_world_m = CamFromWorld(pose);
    ToGl(ClipFromCamera(intrinsics, target->width(), target->height(), depth) * cam_from_world_m, clip_from_world_gl);
    ToGl(cam_from_world_m, cam_from_world_gl);
    target->Bind();
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClearDepthf(1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glUseProgram(program.id());
    glUniformMatrix4fv(clip_from_world, 1, GL_FALSE, clip_from_world_gl);
    glUniformMatrix4fv(cam_from_world, 1, GL_FALSE, cam_from_world_gl);
    glUniform1i(mode, mode_value);
    glUniform1f(inverse_cell, static_cast<float>(1.0 / options.texture_cell_m));
    const Eigen::Vector3f light = Eigen::Vector3f(0.3f, 1.0f, 0.5f).normalized();  // from above and the front (+z)
    glUniform3f(light_direction, light.x(), light.y(), light.z());
    glBindVertexArray(vertex_array.get());
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
    RECONAR_RETURN_IF_ERROR(CheckGlError("BunnyRenderer::Draw"));
    return target->ReadRgb(&readback);
  }
};

BunnyRenderer::BunnyRenderer(std::unique_ptr<Gl> gl) : gl_(std::move(gl)) {}
BunnyRenderer::~BunnyRenderer() = default;

Result<std::unique_ptr<BunnyRenderer>> BunnyRenderer::Create(const Mesh& bunny, const BunnySceneOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(ValidateMesh(bunny).WithContext("BunnyRenderer"));
  if (bunny.triangles.empty()) return InvalidArgument("BunnyRenderer: the mesh has no triangles");
  Mesh mesh = bunny;
  if (mesh.normals.empty()) ComputeVertexNormals(&mesh);

  auto gl = std::make_unique<Gl>();
  gl->options = options;
  RECONAR_ASSIGN_OR_RETURN(gl->program, ShaderProgram::Build("bunny scene", kVertexShader, kFragmentShader));
  gl->clip_from_world = gl->program.Uniform("u_clip_from_world");
  gl->cam_from_world = gl->program.Uniform("u_cam_from_world");
  gl->mode = gl->program.Uniform("u_mode");
  gl->inverse_cell = gl->program.Uniform("u_inverse_cell");
  gl->light_direction = gl->program.Uniform("u_light_direction");

  gl->vertex_array = MakeGlVertexArray();
  glBindVertexArray(gl->vertex_array.get());
  gl->positions = MakeGlBuffer();
  glBindBuffer(GL_ARRAY_BUFFER, gl->positions.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.positions.size() * sizeof(Eigen::Vector3f)),
               mesh.positions.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(kPosition);
  glVertexAttribPointer(kPosition, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl->normals = MakeGlBuffer();
  glBindBuffer(GL_ARRAY_BUFFER, gl->normals.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.normals.size() * sizeof(Eigen::Vector3f)),
               mesh.normals.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(kNormal);
  glVertexAttribPointer(kNormal, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl->indices = MakeGlBuffer();
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gl->indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * sizeof(mesh.triangles[0])),
               mesh.triangles.data(), GL_STATIC_DRAW);
  gl->index_count = static_cast<GLsizei>(mesh.triangles.size() * 3);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  RECONAR_RETURN_IF_ERROR(CheckGlError("BunnyRenderer::Create"));

  const int s = options.supersampling;
  RECONAR_ASSIGN_OR_RETURN(gl->color_target, OffscreenTarget::Create(s * options.width, s * options.height, 0));
  RECONAR_ASSIGN_OR_RETURN(gl->depth_target, OffscreenTarget::Create(options.width, options.height, 0));
  return std::unique_ptr<BunnyRenderer>(new BunnyRenderer(std::move(gl)));
}

Status BunnyRenderer::RenderColor(const SfmCamera& camera, const Rigid3& pose, Image<uint8_t>* rgb) {
  RECONAR_RETURN_IF_ERROR(gl_->Draw(camera, pose, &gl_->color_target, 0));
  const int s = gl_->options.supersampling;
  const int width = gl_->options.width;
  const int height = gl_->options.height;
  if (rgb->width() != width || rgb->height() != height || rgb->channels() != 3) *rgb = Image<uint8_t>(width, height, 3);
  const Image<uint8_t>& fine = gl_->readback;
  const int samples = s * s;
  for (int y = 0; y < height; ++y) {
    uint8_t* out = rgb->row(y);
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int dy = 0; dy < s; ++dy) {
          const uint8_t* in = fine.row(s * y + dy) + 3 * s * x + c;
          for (int dx = 0; dx < s; ++dx) sum += in[3 * dx];
        }
        out[3 * x + c] = static_cast<uint8_t>((sum + samples / 2) / samples);
      }
    }
  }
  return Status::Ok();
}

Status BunnyRenderer::RenderDepth(const SfmCamera& camera, const Rigid3& pose, Image<float>* depth) {
  RECONAR_RETURN_IF_ERROR(gl_->Draw(camera, pose, &gl_->depth_target, 1));
  const int width = gl_->options.width;
  const int height = gl_->options.height;
  if (depth->width() != width || depth->height() != height || depth->channels() != 1) {
    *depth = Image<float>(width, height, 1);
  }
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = gl_->readback.row(y);
    float* out = depth->row(y);
    for (int x = 0; x < width; ++x) {
      const int q = (in[3 * x] << 16) | (in[3 * x + 1] << 8) | in[3 * x + 2];
      out[x] = static_cast<float>(q * (kDepthEncodingRangeM / kDepthEncodingSteps));
    }
  }
  return Status::Ok();
}

Status BunnyRenderer::RenderCoverage(const SfmCamera& camera, const Rigid3& pose, Image<float>* coverage) {
  RECONAR_RETURN_IF_ERROR(gl_->Draw(camera, pose, &gl_->color_target, 1));
  const int s = gl_->options.supersampling;
  const int width = gl_->options.width;
  const int height = gl_->options.height;
  if (coverage->width() != width || coverage->height() != height || coverage->channels() != 1) {
    *coverage = Image<float>(width, height, 1);
  }
  const float per_sample = 1.0f / static_cast<float>(s * s);
  for (int y = 0; y < height; ++y) {
    float* out = coverage->row(y);
    for (int x = 0; x < width; ++x) {
      int covered = 0;
      for (int dy = 0; dy < s; ++dy) {
        const uint8_t* in = gl_->readback.row(s * y + dy) + 3 * s * x;
        for (int dx = 0; dx < s; ++dx) covered += (in[3 * dx] | in[3 * dx + 1] | in[3 * dx + 2]) != 0 ? 1 : 0;
      }
      out[x] = covered * per_sample;
    }
  }
  return Status::Ok();
}

Result<BunnySceneReport> WriteBunnyProject(const Mesh& bunny, const BunnyProjectOptions& options,
                                           const std::string& project_dir) {
  const BunnySceneOptions& scene = options.scene;
  RECONAR_RETURN_IF_ERROR(scene.Check());
  Mesh mesh = bunny;
  if (mesh.normals.empty()) ComputeVertexNormals(&mesh);
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<BunnyRenderer> renderer, BunnyRenderer::Create(mesh, scene));
  const Reconstruction model = MakeBunnyCameras(mesh, scene);
  const SfmCamera& camera = model.cameras[0];

  const Project project(project_dir);
  const std::string images_dir = project_dir + "/images";
  RECONAR_RETURN_IF_ERROR(CreateDirectories(images_dir));

  BunnySceneReport report;
  report.views = static_cast<int>(model.images.size());
  report.pixel_footprint_at_center_m = scene.distance_m / scene.focal_px;
  report.visibility.views_per_vertex.assign(mesh.positions.size(), 0);
  const double min_cos = std::cos(options.visibility_max_angle_deg * M_PI / 180.0);

  std::vector<ProjectImage> list;
  Image<uint8_t> rgb;
  Image<float> depth;
  for (const SfmImage& image : model.images) {
    RECONAR_RETURN_IF_ERROR(renderer->RenderColor(camera, image.cam_from_world, &rgb));
    const std::string path = images_dir + "/" + image.name;
    RECONAR_RETURN_IF_ERROR(WritePng(path, rgb.view(), 3));
    ProjectImage entry;
    entry.name = image.name;
    entry.path = path;
    entry.width = camera.width;
    entry.height = camera.height;
    entry.focal_px = camera.focal;
    entry.focal_source = "ground-truth";
    list.push_back(entry);

    RECONAR_RETURN_IF_ERROR(renderer->RenderDepth(camera, image.cam_from_world, &depth));
    int64_t foreground = 0;
    for (int y = 0; y < depth.height(); ++y) {
      for (int x = 0; x < depth.width(); ++x) foreground += depth.row(y)[x] > 0.0f ? 1 : 0;
    }
    report.mean_foreground_fraction += static_cast<double>(foreground) / (depth.width() * depth.height());

    const Eigen::Vector3d center = image.Center();
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const Eigen::Vector3d world = mesh.positions[i].cast<double>();
      const Eigen::Vector3d cam = image.cam_from_world * world;
      if (cam.z() <= 0.0) continue;
      const Eigen::Vector2d pixel = camera.Project(cam);
      const int x = static_cast<int>(std::lround(pixel.x()));
      const int y = static_cast<int>(std::lround(pixel.y()));
      if (x < 0 || y < 0 || x >= depth.width() || y >= depth.height()) continue;
      if (std::abs(depth.row(y)[x] - cam.z()) > options.visibility_depth_tolerance_m) continue;
      const Eigen::Vector3d to_camera = (center - world).normalized();
      if (mesh.normals[i].cast<double>().dot(to_camera) < min_cos) continue;
      ++report.visibility.views_per_vertex[i];
    }
  }
  report.mean_foreground_fraction /= report.views;
  int64_t seen2 = 0;
  int64_t seen3 = 0;
  for (int views : report.visibility.views_per_vertex) {
    seen2 += views >= 2 ? 1 : 0;
    seen3 += views >= 3 ? 1 : 0;
  }
  report.visibility.seen_by_2_fraction = static_cast<double>(seen2) / mesh.positions.size();
  report.visibility.seen_by_3_fraction = static_cast<double>(seen3) / mesh.positions.size();

  RECONAR_RETURN_IF_ERROR(project.WriteImageList(list));
  RECONAR_RETURN_IF_ERROR(WriteColmapTextModel(model, project.SparseDir()));
  return report;
}

}  // namespace testing
}  // namespace reconar
