#include "render/ar/photo_render.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

#include "core/base/atomic_file.h"
#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "core/mvs/undistort.h"
#include "core/pipeline/project.h"
#include "core/pipeline/texture_stage.h"
#include "core/sfm/model_io.h"
#include "platform/egl/egl_context.h"
#include "render/ar/ar_project.h"
#include "render/mesh_drawable.h"
#include "render/overlay_renderer.h"
#include "render/preview.h"

namespace reconar {
namespace {

// Depths that hold the whole model in front of the camera.
DepthRange DepthRangeFor(const Mesh& mesh, const Rigid3& cam_from_world) {
  double nearest = INFINITY, farthest = 0.0;
  for (const Eigen::Vector3f& p : mesh.positions) {
    const double z = (cam_from_world * p.cast<double>()).z();
    if (z > 0.0) {
      nearest = std::min(nearest, z);
      farthest = std::max(farthest, z);
    }
  }
  DepthRange range;
  if (!(farthest > 0.0)) return range;
  range.far_m = 1.01 * farthest;
  range.near_m = std::max(0.5 * nearest, range.far_m * 1e-5);
  return range;
}

// White where the two renders agree (the model), black where the background shows.
Image<uint8_t> CoverageMask(const Image<uint8_t>& on_black, const Image<uint8_t>& on_white, double* fraction) {
  Image<uint8_t> mask(on_black.width(), on_black.height(), 1);
  size_t covered = 0;
  for (int y = 0; y < mask.height(); ++y) {
    const uint8_t* a = on_black.row(y);
    const uint8_t* b = on_white.row(y);
    uint8_t* m = mask.row(y);
    for (int x = 0; x < mask.width(); ++x) {
      const bool same = a[3 * x] == b[3 * x] && a[3 * x + 1] == b[3 * x + 1] && a[3 * x + 2] == b[3 * x + 2];
      m[x] = same ? 255 : 0;
      covered += same;
    }
  }
  *fraction = static_cast<double>(covered) / static_cast<double>(mask.width() * mask.height());
  return mask;
}

}  // namespace

const char* RenderExposureName(RenderExposure exposure) {
  switch (exposure) {
    case RenderExposure::kPhotoGain: return "photo's gain";
    case RenderExposure::kExif: return "EXIF";
    case RenderExposure::kTexture: break;
  }
  return "texture";
}

Result<PhotoRenderReport> RenderFromPhotos(const std::string& project_dir, const PhotoRenderOptions& options) {
  if (options.image_names.empty()) return InvalidArgument("render: no photo named");
  if (options.out_dir.empty()) return InvalidArgument("render: no output directory (--out)");
  const Project project(project_dir);
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(project.SparseDir()));
  RECONAR_ASSIGN_OR_RETURN(const auto path_of, project.PhotoPathsByName());
  std::map<std::string, const SfmImage*> registered;
  for (const SfmImage& image : model.images) {
    if (image.registered) registered[image.name] = &image;
  }
  for (const std::string& name : options.image_names) {
    if (registered.count(name) == 0) {
      return InvalidArgument("render: " + name + " is not a registered photo of " + project_dir);
    }
  }

  PhotoRenderReport report;
  report.model_path = options.model_path;
  if (report.model_path.empty()) report.model_path = ProjectModelPath(project_dir);
  RECONAR_ASSIGN_OR_RETURN(const ArModel ar_model, LoadArModel(report.model_path, 0));
  report.textured = !ar_model.texture.empty();
  report.faces = ar_model.mesh.triangles.size();
  RECONAR_RETURN_IF_ERROR(CreateDirectories(options.out_dir));
  // The texture's exposure, when the model is the project's textured model.
  std::optional<TextureExposure> exposure;
  std::error_code error;
  if (report.textured && options.match_photo_exposure &&
      std::filesystem::equivalent(report.model_path, TexturedModelPath(project), error)) {
    Result<TextureExposure> read = ReadTextureExposure(project);
    if (read.ok()) {
      exposure = std::move(*read);
    } else {
      report.warning = read.status().ToString() + "; the texture is drawn at its own exposure";
    }
  }

  EglContextOptions context_options;
  context_options.kind = EglContextKind::kSurfaceless;
  RECONAR_ASSIGN_OR_RETURN(auto context, EglContext::Create(context_options));
  RECONAR_ASSIGN_OR_RETURN(const MeshDrawable drawable,
                           MeshDrawable::Upload(ar_model.mesh, report.textured ? &ar_model.texture : nullptr));
  MeshStyle style;
  style.shading = false;
  for (const std::string& name : options.image_names) {
    const SfmImage& image = *registered[name];
    const SfmCamera& camera = model.cameras[static_cast<size_t>(image.camera_id)];
    RenderExposure exposed = RenderExposure::kTexture;
    Eigen::Vector3f gain = Eigen::Vector3f::Ones();
    if (exposure) {
      const auto own = std::find_if(exposure->photos.begin(), exposure->photos.end(),
                                    [&](const PhotoExposure& photo) { return photo.name == name; });
      const auto path = path_of.find(name);
      if (own != exposure->photos.end()) {
        gain = own->gain;
        exposed = RenderExposure::kPhotoGain;
      } else if (exposure->fit && path != path_of.end()) {
        const Result<ImageHeader> header = ReadImageHeader(path->second);
        if (header.ok()) {
          if (const std::optional<double> log_exposure = LogExposure(header->exif)) {
            gain = exposure->fit->Predict(*log_exposure);
            exposed = RenderExposure::kExif;
          }
        }
      }
    }
    style.gain = {1.0f / gain.x(), 1.0f / gain.y(), 1.0f / gain.z()};
    CameraIntrinsics intrinsics = camera.Intrinsics();
    intrinsics.k1 = intrinsics.k2 = 0.0;
    Image<uint8_t> renders[2];
    for (int background = 0; background < 2; ++background) {
      OverlayRendererOptions renderer_options;
      renderer_options.width = camera.width;
      renderer_options.height = camera.height;
      renderer_options.samples = 0;
      const float clear = static_cast<float>(background);
      renderer_options.clear_color = {clear, clear, clear};
      renderer_options.depth = DepthRangeFor(ar_model.mesh, image.cam_from_world);
      RECONAR_ASSIGN_OR_RETURN(auto renderer, OverlayRenderer::Create(renderer_options));
      RECONAR_RETURN_IF_ERROR(renderer->BeginFrame());
      RECONAR_RETURN_IF_ERROR(renderer->DrawMesh(drawable, intrinsics, image.cam_from_world.Matrix(), style));
      RECONAR_RETURN_IF_ERROR(renderer->ReadRgb(&renders[background]));
    }
    double coverage = 0.0;
    const Image<uint8_t> mask = CoverageMask(renders[0], renders[1], &coverage);
    const std::string base = options.out_dir + "/" + name;
    RECONAR_RETURN_IF_ERROR(WritePng(base + ".png", renders[0].view(), 3));
    RECONAR_RETURN_IF_ERROR(WritePng(base + ".mask.png", mask.view(), 1));
    if (options.write_photos) {
      const auto path = path_of.find(name);
      if (path == path_of.end()) return NotFound("render: " + name + " is not in " + project.ImageListPath());
      RECONAR_ASSIGN_OR_RETURN(const DecodedImage photo, ReadImage(path->second));
      RECONAR_ASSIGN_OR_RETURN(const DenseView undistorted, UndistortView(photo.rgb, camera, image.cam_from_world, 0));
      RECONAR_RETURN_IF_ERROR(WritePng(base + ".photo.png", undistorted.rgb.view(), 3));
    }
    report.written.push_back(base + ".png");
    report.coverage.push_back(coverage);
    report.exposure.push_back(exposed);
    report.gain.push_back(gain);
  }
  return report;
}

Status WriteModelPreview(const std::string& model_path, const Eigen::Vector3d& up, const std::string& png_path) {
  RECONAR_ASSIGN_OR_RETURN(const ArModel model, LoadArModel(model_path, 0));
  Status written = WritePreview(model.mesh, model.texture.empty() ? nullptr : &model.texture, up, png_path);
  return written.ok() ? written : written.WithContext(model_path);
}

}  // namespace reconar
