#include "core/pipeline/texture_stage.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "core/base/atomic_file.h"
#include "core/base/fnv_hash.h"
#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/base/memory_usage.h"
#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/obj_io.h"
#include "core/mesh/simplify.h"
#include "core/pipeline/project_lock.h"
#include "core/pipeline/stage_record.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

// The mesh stage's mesh in the first readable format it wrote.
Result<std::string> ProjectMeshPath(const Project& project) {
  for (const char* format : {"ply", "glb", "obj"}) {
    const std::string path = project.MeshDir() + "/mesh." + format;
    if (std::filesystem::exists(path)) return path;
  }
  return FailedPrecondition(project.MeshDir() + ": no mesh (mesh.ply, .glb or .obj); run the mesh stage first");
}

}  // namespace

Status TextureStageOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(texture.Check());
  if (memory_budget_bytes == 0) return InvalidArgument("texture: the memory budget must be positive");
  return Status::Ok();
}

std::string TextureStageSettings(const TextureStageOptions& options) {
  std::vector<std::string> exclude = options.exclude;
  std::sort(exclude.begin(), exclude.end());
  Fnv1a64 hash;
  for (const std::string& name : exclude) {
    hash.Add(name);
    hash.Add("/");
  }
  // 40 bits of the digest: exact in the record's 12 significant digits.
  return StageRecord::Settings({{"version", 1},
                                {"max_faces", static_cast<double>(options.max_faces)},
                                {"atlas_size", options.texture.atlas_size},
                                {"max_pages", options.texture.max_pages},
                                {"exclude", static_cast<double>(hash.value() >> 24)}});
}

Result<TextureStageReport> RunTextureStage(const Project& project, const TextureStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_ASSIGN_OR_RETURN(const ProjectLock lock, LockProject(project));
  const auto start = std::chrono::steady_clock::now();
  ResetPeakResidentBytes();
  TextureStageReport report;
  RECONAR_ASSIGN_OR_RETURN(report.mesh_path, ProjectMeshPath(project));
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(project.SparseDir()));
  RECONAR_ASSIGN_OR_RETURN(const auto path_of, project.PhotoPathsByName());

  std::set<std::string> registered;
  for (const SfmImage& image : model.images) {
    if (image.registered) registered.insert(image.name);
  }
  for (const std::string& name : options.exclude) {
    if (registered.count(name) == 0) {
      return InvalidArgument("texture: --exclude " + name + " is not a registered photo of " + project.root());
    }
  }
  report.excluded = options.exclude;
  const std::set<std::string> excluded(options.exclude.begin(), options.exclude.end());

  std::vector<TexturePhoto> photos;
  std::vector<std::string> paths;
  std::vector<std::optional<double>> log_exposures;
  std::string first_reason;
  for (const SfmImage& image : model.images) {
    if (!image.registered || excluded.count(image.name) != 0) continue;
    const auto it = path_of.find(image.name);
    std::string reason;
    std::optional<double> log_exposure;
    if (it == path_of.end()) {
      reason = "not in " + project.ImageListPath();
    } else if (const auto header = ReadImageHeader(it->second); !header.ok()) {
      reason = header.status().ToString();
    } else {
      log_exposure = LogExposure(header->exif);
    }
    if (!reason.empty()) {
      if (first_reason.empty()) first_reason = reason;
      std::fprintf(stderr, "warning: texture: photo %s left out: %s\n", image.name.c_str(), reason.c_str());
      report.unreadable.push_back(image.name);
      continue;
    }
    TexturePhoto photo;
    photo.name = image.name;
    photo.camera = model.cameras[static_cast<size_t>(image.camera_id)];
    photo.cam_from_world = image.cam_from_world;
    photos.push_back(photo);
    paths.push_back(it->second);
    log_exposures.push_back(log_exposure);
  }
  if (photos.empty()) {
    std::string why = "texture: no registered photo to texture from";
    if (!report.unreadable.empty()) {
      why += ": none of the " + std::to_string(report.unreadable.size()) + " could be read (" + first_reason + ")";
    }
    return FailedPrecondition(why);
  }

  RECONAR_ASSIGN_OR_RETURN(Mesh mesh, ReadMeshFile(report.mesh_path));
  if (mesh.triangles.empty()) return FailedPrecondition(report.mesh_path + ": no triangles to texture");
  report.faces_in = mesh.triangles.size();
  RECONAR_ASSIGN_OR_RETURN(const SimplifyReport simplify, SimplifyToFaceBudget(options.max_faces, &mesh));
  report.simplified = simplify.simplified;

  TextureOptions texture = options.texture;
  texture.memory_budget_bytes = options.memory_budget_bytes;
  texture.num_threads = options.num_threads;
  texture.show_progress = options.show_progress;
  const PhotoLoader load = [&](size_t index) -> Result<Image<uint8_t>> {
    RECONAR_ASSIGN_OR_RETURN(DecodedImage decoded, ReadImage(paths[index]));
    return std::move(decoded.rgb);
  };
  RECONAR_ASSIGN_OR_RETURN(const TexturedMesh textured, TextureMesh(mesh, photos, load, texture, &report.texture));
  for (size_t i = 0; i < photos.size(); ++i) {
    report.photo_exposures.push_back({photos[i].name, report.texture.photo_gains[i], log_exposures[i]});
  }
  report.exposure_fit = FitExposureGains(log_exposures, report.texture.photo_gains);

  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.MeshDir()));
  std::vector<EncodedTexturePage> pngs;
  std::vector<ObjTextureFile> page_files;
  std::vector<std::string> png_paths;
  for (size_t k = 0; k < textured.pages.size(); ++k) {
    const TexturePage& page = textured.pages[k];
    RECONAR_ASSIGN_OR_RETURN(std::string png, EncodePng(page.image.view(), 3, kPngFastCompression));
    png_paths.push_back(project.MeshDir() + "/" + TexturePageFileName(k));
    RECONAR_RETURN_IF_ERROR(WriteFileAtomically(png_paths.back(), png));
    pngs.push_back({page.first_triangle, std::move(png)});
    page_files.push_back({page.first_triangle, TexturePageFileName(k)});
  }
  RECONAR_RETURN_IF_ERROR(RemoveTexturePagesFrom(project, textured.pages.size()));
  const TexturedModelFiles files = TexturedModelFilesOf(project);
  RECONAR_RETURN_IF_ERROR(WriteTexturedObj(files.obj, textured.mesh, page_files));
  RECONAR_RETURN_IF_ERROR(WriteTexturedGlb(files.glb, textured.mesh, pngs));
  report.paths = {files.glb, files.obj, files.mtl};
  report.paths.insert(report.paths.end(), png_paths.begin(), png_paths.end());
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.peak_rss_bytes = PeakResidentBytes();
  report.report_path = files.report;
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, TextureReportJson(report)));
  return report;
}

TexturedModelFiles TexturedModelFilesOf(const Project& project) {
  const std::string dir = project.MeshDir() + "/";
  return {dir + "textured.glb", dir + "textured.obj", dir + "textured.mtl", dir + "texture_report.json"};
}

std::string TexturePageFileName(size_t page) {
  return page == 0 ? "textured.png" : "textured_" + std::to_string(page) + ".png";
}

Status RemoveTexturePagesFrom(const Project& project, size_t first_page) {
  // The pages are written in order, so those left behind are a run from first_page on.
  for (size_t page = first_page;; ++page) {
    const std::string path = project.MeshDir() + "/" + TexturePageFileName(page);
    std::error_code error;
    if (!std::filesystem::exists(path, error) && page > 0) return Status::Ok();
    RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(path));
  }
}

Status RemoveTexturedModel(const Project& project) {
  const TexturedModelFiles files = TexturedModelFilesOf(project);
  for (const std::string* path : {&files.report, &files.glb, &files.obj, &files.mtl}) {
    RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(*path));
  }
  return RemoveTexturePagesFrom(project, 0);
}

namespace {

// Three numbers of an array member, or nothing.
std::optional<Eigen::Vector3d> Vector3Member(const JsonValue& object, const char* key) {
  const JsonValue* array = object.Find(key);
  if (array == nullptr || !array->is_array() || array->size() != 3) return std::nullopt;
  Eigen::Vector3d v;
  for (size_t c = 0; c < 3; ++c) {
    if (!(*array)[c].is_number()) return std::nullopt;
    v[static_cast<int>(c)] = (*array)[c].number();
  }
  return v;
}

}  // namespace

Result<TextureExposure> ReadTextureExposure(const Project& project) {
  const std::string path = TexturedModelFilesOf(project).report;
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return FailedPrecondition(path + ": no texture report (reconar texture)");
  RECONAR_ASSIGN_OR_RETURN(const JsonValue report, ReadJsonFile(path));
  TextureExposure exposure;
  const JsonValue* photos = report.Find("photo_exposures");
  if (photos == nullptr) return exposure;  // a report of an older version: no exposures
  if (!photos->is_array()) return FileError(StatusCode::kCorruptData, path, "photo_exposures is not an array");
  for (size_t i = 0; i < photos->size(); ++i) {
    const JsonValue& photo = (*photos)[i];
    const JsonValue* name = photo.Find("name");
    const std::optional<Eigen::Vector3d> gain = Vector3Member(photo, "gain");
    if (name == nullptr || !name->is_string() || !gain) {
      return FileError(StatusCode::kCorruptData, path, "photo_exposures[" + std::to_string(i) + "] is not a name and a gain");
    }
    PhotoExposure entry;
    entry.name = name->string();
    entry.gain = gain->cast<float>();
    if (const JsonValue* log_exposure = photo.Find("log_exposure"); log_exposure && log_exposure->is_number()) {
      entry.log_exposure = log_exposure->number();
    }
    exposure.photos.push_back(std::move(entry));
  }
  if (const JsonValue* fit = report.Find("exposure_fit")) {
    const std::optional<Eigen::Vector3d> intercept = Vector3Member(*fit, "intercept"), slope = Vector3Member(*fit, "slope");
    if (!intercept || !slope) return FileError(StatusCode::kCorruptData, path, "exposure_fit has no intercept and slope");
    ExposureFit parsed;
    parsed.intercept = *intercept;
    parsed.slope = *slope;
    exposure.fit = parsed;
  }
  return exposure;
}

std::string TextureReportJson(const TextureStageReport& report) {
  const TextureReport& t = report.texture;
  JsonWriter json(2);
  json.BeginObject();
  json.Key("mesh").String(report.mesh_path);
  json.Key("faces_in").Int(static_cast<long long>(report.faces_in));
  json.Key("simplified").Bool(report.simplified);
  json.Key("faces").Int(static_cast<long long>(t.faces));
  json.Key("photos").Int(static_cast<long long>(t.photos));
  json.Key("photos_used").Int(static_cast<long long>(t.photos_used));
  json.Key("excluded").BeginArray();
  for (const std::string& name : report.excluded) json.String(name);
  json.EndArray();
  json.Key("unreadable").BeginArray();
  for (const std::string& name : report.unreadable) json.String(name);
  json.EndArray();
  json.Key("candidates").Int(static_cast<long long>(t.candidates));
  json.Key("inconsistent_candidates").Int(static_cast<long long>(t.inconsistent_candidates));
  json.Key("exposure_gain_min").Double(t.min_gain).Key("exposure_gain_max").Double(t.max_gain);
  json.Key("textured_faces").Int(static_cast<long long>(t.textured_faces));
  json.Key("untextured_faces").Int(static_cast<long long>(t.untextured_faces));
  json.Key("patches").Int(static_cast<long long>(t.patches));
  json.Key("labelling_sweeps").Int(t.labelling_sweeps);
  json.Key("labelling_energy_start").Double(t.labelling_energy_start);
  json.Key("labelling_energy_end").Double(t.labelling_energy_end);
  json.Key("seam_edges").Int(static_cast<long long>(t.seam_edges));
  json.Key("seam_step_before").Double(t.seam_step_before);
  json.Key("seam_step_after").Double(t.seam_step_after);
  json.Key("photo_exposures").BeginArray();
  for (const PhotoExposure& photo : report.photo_exposures) {
    json.BeginObject().Key("name").String(photo.name);
    json.Key("gain").BeginArray().Double(photo.gain.x()).Double(photo.gain.y()).Double(photo.gain.z()).EndArray();
    if (photo.log_exposure) json.Key("log_exposure").Double(*photo.log_exposure);
    json.EndObject();
  }
  json.EndArray();
  if (report.exposure_fit) {
    const ExposureFit& fit = *report.exposure_fit;
    json.Key("exposure_fit").BeginObject();
    json.Key("intercept").BeginArray().Double(fit.intercept.x()).Double(fit.intercept.y()).Double(fit.intercept.z());
    json.EndArray();
    json.Key("slope").BeginArray().Double(fit.slope.x()).Double(fit.slope.y()).Double(fit.slope.z()).EndArray();
    json.Key("photos").Int(static_cast<long long>(fit.photos)).Key("correlation").Double(fit.correlation);
    json.EndObject();
  }
  json.Key("atlas_pages").Int(static_cast<long long>(t.atlas_pages));
  json.Key("atlas_width").Int(t.atlas_width).Key("atlas_height").Int(t.atlas_height);
  json.Key("texels_per_pixel").Double(t.texels_per_pixel);
  json.Key("atlas_fill").Double(t.atlas_fill);
  json.Key("photos_kept_decoded").Int(static_cast<long long>(t.photos_kept_decoded));
  json.Key("seconds_candidates").Double(t.seconds_candidates);
  json.Key("seconds_labelling").Double(t.seconds_labelling);
  json.Key("seconds_seams").Double(t.seconds_seams);
  json.Key("seconds_atlas").Double(t.seconds_atlas);
  json.Key("seconds").Double(report.seconds);
  json.Key("peak_rss_mib").Double(Mib(report.peak_rss_bytes));
  json.Key("files").BeginArray();
  for (const std::string& path : report.paths) json.String(path);
  json.EndArray();
  json.EndObject();
  return json.str();
}

}  // namespace reconar
