#pragma once
// Texture stage: PROJECT/mesh/mesh.{ply,glb,obj} and the registered photos -> the mesh simplified
// to a face budget and textured from the photos (core/texture/texture_mesh.h) ->
// PROJECT/mesh/textured.{png,obj,mtl,glb} (textured_1.png, ... for the texture's further pages) and
// mesh/texture_report.json, each atomically, the report last.
//
// Face budget: the texture carries the surface's detail, so the geometry needs only its shape:
// kTexturedMaxFaces (a third of the handheld budget the untextured mesh keeps) leaves the GPU the
// time for the video and the texture lookups, and makes view selection and packing 3x faster.
// Photos: every registered photo but the excluded ones; a photo missing on disk, or whose header
// does not read, is left out with a warning (its name in the report), so that the others still
// texture the model. When texturing cannot be done (no photo sees the mesh, a photo that fails to
// decode) the stage fails with the reason and the untextured mesh stays as it was.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/project.h"
#include "core/texture/exposure_fit.h"
#include "core/texture/texture_mesh.h"

namespace reconar {

inline constexpr size_t kTexturedMaxFaces = 160000;

struct TextureStageOptions {
  size_t max_faces = kTexturedMaxFaces;  // 0: texture the mesh as it is
  std::vector<std::string> exclude;      // photo names left out
  TextureOptions texture;                // its memory budget and threads are the stage's
  size_t memory_budget_bytes = kDefaultMemoryBudgetBytes;
  int num_threads = 0;
  bool show_progress = false;

  Status Check() const;
};

// A textured photo's exposure: its gain (what brings its colours to the texture's exposure) and
// log H from its EXIF (core/texture/exposure_fit.h) when it has the settings.
struct PhotoExposure {
  std::string name;
  Eigen::Vector3f gain = Eigen::Vector3f::Ones();
  std::optional<double> log_exposure;
};

struct TextureStageReport {
  std::string mesh_path;  // read
  size_t faces_in = 0;    // of the mesh read
  bool simplified = false;
  TextureReport texture;
  std::vector<std::string> excluded;  // as asked
  std::vector<std::string> unreadable;  // photos left out because they do not read
  std::vector<PhotoExposure> photo_exposures;  // the photos textured from
  std::optional<ExposureFit> exposure_fit;     // gains against EXIF exposure, when it says something
  double seconds = 0.0;
  size_t peak_rss_bytes = 0;
  std::vector<std::string> paths;  // written
  std::string report_path;
};

// The settings the stage's record holds (core/pipeline/stage_record.h).
std::string TextureStageSettings(const TextureStageOptions& options);

// FailedPrecondition without a mesh or a sparse model; InvalidArgument for an excluded name that
// is no registered photo of the project.
Result<TextureStageReport> RunTextureStage(const Project& project, const TextureStageOptions& options);

std::string TextureReportJson(const TextureStageReport& report);

// What `reconar render` needs of the texture's exposure: mesh/texture_report.json's
// photo_exposures and exposure_fit. FailedPrecondition without a report; kCorruptData naming the
// file for one that does not parse.
struct TextureExposure {
  std::vector<PhotoExposure> photos;
  std::optional<ExposureFit> fit;
};
Result<TextureExposure> ReadTextureExposure(const Project& project);

// The stage's files in PROJECT/mesh, but for the texture's pages (TexturePageFileName).
struct TexturedModelFiles {
  std::string glb;     // textured.glb, the stage's main output
  std::string obj;     // textured.obj
  std::string mtl;     // textured.mtl, the OBJ's materials (WriteTexturedObj names it after the OBJ)
  std::string report;  // texture_report.json
};
TexturedModelFiles TexturedModelFilesOf(const Project& project);

inline std::string TexturedModelPath(const Project& project) { return TexturedModelFilesOf(project).glb; }

// The file of texture page k in the mesh directory: textured.png, textured_1.png, ...
std::string TexturePageFileName(size_t page);

// Removes the page files from page `first_page` on (those a texture of fewer pages left behind).
Status RemoveTexturePagesFrom(const Project& project, size_t first_page);

// Removes the stage's outputs and report: the mesh stage does when it replaces the mesh they were
// made from, so that no view or render shows a textured model of a mesh that is gone.
Status RemoveTexturedModel(const Project& project);

}  // namespace reconar
