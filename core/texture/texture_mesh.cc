#include "core/texture/texture_mesh.h"

#include <chrono>
#include <memory>
#include <set>

#include "core/base/memory_usage.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/texture/face_adjacency.h"
#include "core/texture/face_views.h"
#include "core/texture/photo_gains.h"
#include "core/texture/seam_levelling.h"
#include "core/texture/texture_atlas.h"
#include "core/texture/view_labelling.h"

namespace reconar {
namespace {

// Patches smaller than this join a neighbour's photo where they can (view_labelling.h).
constexpr size_t kMinPatchFaces = 16;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Result<Image<uint8_t>> LoadChecked(const PhotoLoader& load, const TexturePhoto& photo, size_t index) {
  RECONAR_ASSIGN_OR_RETURN(Image<uint8_t> rgb, load(index));
  if (rgb.channels() != 3 || rgb.width() != photo.camera.width || rgb.height() != photo.camera.height) {
    return InvalidArgument("texture: photo " + photo.name + " is " + std::to_string(rgb.width()) + " x " +
                           std::to_string(rgb.height()) + " x " + std::to_string(rgb.channels()) +
                           ", its camera " + std::to_string(photo.camera.width) + " x " +
                           std::to_string(photo.camera.height) + " x 3");
  }
  return rgb;
}

}  // namespace

Status TextureOptions::Check() const {
  if (atlas_size < 64 || (atlas_size & (atlas_size - 1)) != 0) {
    return InvalidArgument("texture: the atlas size must be a power of two of at least 64, got " +
                           std::to_string(atlas_size));
  }
  if (max_pages < 1) return InvalidArgument("texture: at least one atlas page, got " + std::to_string(max_pages));
  if (padding_texels < 1 || padding_texels > 64) return InvalidArgument("texture: padding must be 1..64 texels");
  if (raster_long_side < 16) return InvalidArgument("texture: raster_long_side must be at least 16");
  if (!(min_view_cosine >= 0.0 && min_view_cosine < 1.0)) return InvalidArgument("texture: min_view_cosine in [0, 1)");
  if (!(depth_tolerance > 0.0)) return InvalidArgument("texture: depth_tolerance must be positive");
  if (!(smoothness >= 0.0)) return InvalidArgument("texture: smoothness must be non-negative");
  if (max_labelling_sweeps < 0 || blend_rings < 0) return InvalidArgument("texture: negative sweeps or rings");
  return Status::Ok();
}

Result<TexturedMesh> TextureMesh(const Mesh& mesh, const std::vector<TexturePhoto>& photos, const PhotoLoader& load,
                                 const TextureOptions& options, TextureReport* report) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(ValidateMesh(mesh));
  if (mesh.triangles.empty()) return InvalidArgument("texture: the mesh has no triangle");
  const auto start = std::chrono::steady_clock::now();
  *report = TextureReport();
  report->faces = mesh.triangles.size();
  report->photos = photos.size();
  const int num_threads = ThreadPool::ResolveThreadCount(options.num_threads);

  std::vector<PhotoProjector> projectors;
  for (const TexturePhoto& photo : photos) {
    if (!photo.camera.IsValid() || photo.camera.width <= 0 || photo.camera.height <= 0) {
      return InvalidArgument("texture: photo " + photo.name + " has no valid camera");
    }
    projectors.emplace_back(photo);
  }
  // The atlas pages may take half the budget (RGB texels, coverage, the PNG). Decoded photos are
  // kept for the atlas while the process stays under the budget less the pages' share, measured
  // as each photo is done: the resident set then holds every photo being worked on, so photos
  // decided at once cannot together overshoot.
  const size_t page_bytes =
      static_cast<size_t>(options.atlas_size) * static_cast<size_t>(options.atlas_size) * (3 + 1 + 3);
  int max_pages = options.max_pages;
  if (options.memory_budget_bytes > 0) {
    max_pages = static_cast<int>(std::clamp<size_t>(options.memory_budget_bytes / 2 / page_bytes, 1,
                                                    static_cast<size_t>(max_pages)));
  }
  const size_t atlas_bytes = page_bytes * static_cast<size_t>(max_pages);
  auto may_keep = [&]() {
    return options.memory_budget_bytes == 0 ||
           CurrentMemoryUsage().resident_bytes + atlas_bytes <= options.memory_budget_bytes;
  };

  // 1. Candidates.
  auto phase = std::chrono::steady_clock::now();
  const FaceGeometry geometry(mesh);
  std::vector<std::vector<FaceCandidate>> per_photo(photos.size());
  std::vector<ReducedPhoto> reduced(photos.size());
  std::vector<Image<uint8_t>> kept(photos.size());
  std::vector<CandidateScratch> scratch(static_cast<size_t>(num_threads));
  std::vector<Status> errors(photos.size());
  {
    std::unique_ptr<Progress> progress;
    if (options.show_progress) progress = std::make_unique<Progress>("texture: photos", photos.size());
    ThreadPool pool(num_threads);
    pool.ParallelFor(0, photos.size(), [&](size_t i, int thread) {
      auto rgb = LoadChecked(load, photos[i], i);
      if (!rgb.ok()) {
        errors[i] = rgb.status();
      } else {
        FindFaceCandidates(mesh, geometry, static_cast<int>(i), projectors[i], *rgb, options,
                           &scratch[static_cast<size_t>(thread)], &per_photo[i], &reduced[i]);
        if (may_keep()) kept[i] = std::move(*rgb);
      }
      if (progress) progress->Advance();
    });
  }
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);
  for (const Image<uint8_t>& image : kept) report->photos_kept_decoded += !image.empty();
  scratch.clear();
  FaceCandidateTable table = GroupByFace(mesh.triangles.size(), per_photo);
  per_photo.clear();
  report->candidates = table.candidates.size();
  report->seconds_candidates = SecondsSince(phase);

  // 2. Labels and patches.
  phase = std::chrono::steady_clock::now();
  std::vector<Eigen::Vector3f> gains(photos.size(), Eigen::Vector3f::Ones());
  if (options.level_exposure) {
    gains = EstimatePhotoGains(table, photos.size());
    ApplyPhotoGains(gains, &table);
  }
  if (options.check_photo_consistency) report->inconsistent_candidates = DropInconsistentCandidates(&table);
  WeighCandidates(&table);
  const std::vector<std::array<int, 3>> neighbours = FaceNeighbours(mesh);
  LabellingReport labelling;
  std::vector<int> labels = LabelFaces(table, neighbours, options.smoothness, options.max_labelling_sweeps, &labelling);
  report->faces_merged = MergeSmallPatches(table, neighbours, kMinPatchFaces, &labels);
  report->labelling_sweeps = labelling.sweeps;
  report->labelling_energy_start = labelling.energy_start;
  report->labelling_energy_end = labelling.energy_end;
  const TexturePatches patches = FindPatches(labels, neighbours);
  report->patches = patches.photo.size();
  std::set<int> used(patches.photo.begin(), patches.photo.end());
  report->photos_used = used.size();
  report->photo_gains = gains;
  for (const Eigen::Vector3f& gain : gains) {
    report->min_gain = std::min(report->min_gain, static_cast<double>(gain.minCoeff()));
    report->max_gain = std::max(report->max_gain, static_cast<double>(gain.maxCoeff()));
  }
  for (const int label : labels) (label >= 0 ? report->textured_faces : report->untextured_faces) += 1;
  report->seconds_labelling = SecondsSince(phase);
  if (patches.photo.empty()) {
    return FailedPrecondition("texture: no photo sees any face of the mesh (" + std::to_string(photos.size()) +
                              " photos, " + std::to_string(mesh.triangles.size()) + " faces)");
  }

  // 3. Seams.
  phase = std::chrono::steady_clock::now();
  const std::vector<SeamEdge> seam_edges = FindSeamEdges(mesh, patches, neighbours);
  const PatchColourCorrection correction =
      options.level_seams ? LevelSeams(mesh, patches, seam_edges, projectors, reduced, gains,
                                       FindPatchConsensus(table, patches), options.blend_rings)
                          : NoCorrection(patches.photo.size());
  reduced.clear();
  report->seconds_seams = SecondsSince(phase);

  // 4. Atlas.
  phase = std::chrono::steady_clock::now();
  RECONAR_ASSIGN_OR_RETURN(
      const AtlasLayout layout,
      PackCharts(MakeCharts(mesh, patches, projectors), options.atlas_size, options.padding_texels, max_pages));
  const PhotoAccess access = [&](size_t photo, Image<uint8_t>* storage, const Image<uint8_t>** pixels) -> Status {
    if (!kept[photo].empty()) {
      *pixels = &kept[photo];
      return Status::Ok();
    }
    RECONAR_ASSIGN_OR_RETURN(*storage, LoadChecked(load, photos[photo], photo));
    *pixels = storage;
    return Status::Ok();
  };
  RECONAR_ASSIGN_OR_RETURN(AtlasFill fill, FillAtlas(mesh, layout, projectors, gains, correction, access, num_threads));
  kept.clear();
  const SeamSteps steps = MeasureSeamSteps(mesh, layout, fill.pages, gains, correction, seam_edges);
  report->seam_edges = seam_edges.size();
  report->seam_step_before = steps.before;
  report->seam_step_after = steps.after;
  TexturedMesh textured;
  std::vector<size_t> page_first_triangle;
  textured.mesh = TexturedChartsMesh(mesh, layout, &page_first_triangle);
  for (size_t page = 0; page < fill.pages.size(); ++page) {
    textured.pages.push_back({page_first_triangle[page], std::move(fill.pages[page])});
  }
  report->atlas_width = layout.pages[0].width;
  report->atlas_height = layout.pages[0].height;
  report->atlas_pages = layout.pages.size();
  report->texels_per_pixel = layout.scale;
  report->atlas_fill = fill.covered_fraction;
  report->seconds_atlas = SecondsSince(phase);
  report->seconds = SecondsSince(start);
  return textured;
}

}  // namespace reconar
