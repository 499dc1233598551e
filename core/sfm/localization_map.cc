#include "core/sfm/localization_map.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/base/elapsed.h"
#include "core/base/thread_pool.h"
#include "core/features/descriptor_distance.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

struct ObservationRef {
  int32_t keyframe;
  int32_t observation;
};

// The candidate with the least summed distance to the others (distances, not squared: the L2
// medoid); ties go to the earlier candidate.
int MedoidOf(const std::vector<const uint8_t*>& candidates) {
  const DescriptorDistanceKernel& kernel = ActiveDescriptorDistanceKernel();
  int best = 0;
  double best_sum = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < candidates.size(); ++i) {
    double sum = 0.0;
    for (size_t j = 0; j < candidates.size(); ++j) {
      if (i != j) sum += std::sqrt(static_cast<double>(kernel.distance(candidates[i], candidates[j])));
    }
    if (sum < best_sum) {
      best_sum = sum;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace

Status MapBuildOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(vocabulary.Check());
  if (max_medoid_candidates < 1) return InvalidArgument("MapBuildOptions: max_medoid_candidates must be >= 1");
  return Status::Ok();
}

int LocalizationMap::num_observations() const {
  int n = 0;
  for (const MapKeyframe& keyframe : keyframes) n += keyframe.num_observations();
  return n;
}

size_t LocalizationMap::memory_bytes() const {
  size_t bytes = sizeof(*this) + points.capacity() * sizeof(Eigen::Vector3d) + colors.capacity() * sizeof(colors[0]) +
                 point_descriptors.capacity();
  for (const MapKeyframe& keyframe : keyframes) {
    bytes += sizeof(keyframe) + keyframe.name.capacity() + keyframe.keypoints.capacity() * sizeof(Eigen::Vector2f) +
             keyframe.point_ids.capacity() * sizeof(int32_t) + keyframe.descriptors.capacity();
  }
  return bytes + vocabulary.memory_bytes() + keyframe_index.memory_bytes();
}

Result<LocalizationMap> BuildLocalizationMap(const Reconstruction& model, const ImageDescriptorLoader& load_descriptors,
                                             const std::string& frame, bool metric, const MapBuildOptions& options,
                                             MapBuildReport* report) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (model.NumRegisteredImages() == 0)
    return FailedPrecondition("localisation map: the model has no registered image");
  if (model.NumPoints() == 0) return FailedPrecondition("localisation map: the model has no 3D point");
  MapBuildReport local_report;
  if (report == nullptr) report = &local_report;
  *report = MapBuildReport();

  LocalizationMap map;
  map.frame = frame;
  map.metric = metric;

  // Keyframes and their observations; model point ids are renumbered densely in order of first use
  // below, so that points seen only through tag corners (no descriptor) are left out.
  auto start = Clock::now();
  std::vector<int32_t> map_id_of(model.points.size(), -1);
  std::vector<int32_t> model_id_of;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    if (image.camera_id < 0 || image.camera_id >= static_cast<int>(model.cameras.size())) {
      return InvalidArgument("localisation map: image " + image.name + " has no camera");
    }
    RECONAR_ASSIGN_OR_RETURN(const std::vector<uint8_t> descriptors, load_descriptors(image));
    const size_t num_described = descriptors.size() / kDescriptorSize;
    if (descriptors.size() % kDescriptorSize != 0 || num_described > image.keypoints.size()) {
      return InvalidArgument("localisation map: image " + image.name + " has " + std::to_string(num_described) +
                             " descriptors for " + std::to_string(image.keypoints.size()) + " keypoints");
    }
    const SfmCamera& camera = model.cameras[static_cast<size_t>(image.camera_id)];
    MapKeyframe keyframe;
    keyframe.name = image.name;
    keyframe.width = camera.width;
    keyframe.height = camera.height;
    keyframe.camera = camera;
    keyframe.cam_from_world = image.cam_from_world;
    for (size_t k = 0; k < num_described && k < image.point3d_ids.size(); ++k) {
      const int point = image.point3d_ids[k];
      if (point < 0 || point >= static_cast<int>(model.points.size()) ||
          model.points[static_cast<size_t>(point)].deleted) {
        continue;
      }
      int32_t& map_id = map_id_of[static_cast<size_t>(point)];
      if (map_id < 0) {
        map_id = static_cast<int32_t>(model_id_of.size());
        model_id_of.push_back(point);
      }
      keyframe.keypoints.push_back(image.keypoints[k].cast<float>());
      keyframe.point_ids.push_back(map_id);
      keyframe.descriptors.insert(keyframe.descriptors.end(),
                                  descriptors.begin() + static_cast<std::ptrdiff_t>(k * kDescriptorSize),
                                  descriptors.begin() + static_cast<std::ptrdiff_t>((k + 1) * kDescriptorSize));
    }
    map.keyframes.push_back(std::move(keyframe));
  }
  if (model_id_of.empty()) return FailedPrecondition("localisation map: no 3D point is observed by a SIFT keypoint");

  // Points, and each point's medoid descriptor over (at most max_medoid_candidates of) its
  // observations, taken evenly along the observation list.
  const int num_points = static_cast<int>(model_id_of.size());
  map.points.resize(static_cast<size_t>(num_points));
  map.colors.resize(static_cast<size_t>(num_points));
  for (int i = 0; i < num_points; ++i) {
    const SfmPoint& point = model.points[static_cast<size_t>(model_id_of[static_cast<size_t>(i)])];
    map.points[static_cast<size_t>(i)] = point.position;
    map.colors[static_cast<size_t>(i)] = point.color;
  }
  std::vector<int32_t> first_ref(static_cast<size_t>(num_points) + 1, 0);
  for (const MapKeyframe& keyframe : map.keyframes) {
    for (int32_t id : keyframe.point_ids) ++first_ref[static_cast<size_t>(id) + 1];
  }
  for (int i = 0; i < num_points; ++i) first_ref[static_cast<size_t>(i) + 1] += first_ref[static_cast<size_t>(i)];
  std::vector<ObservationRef> refs(static_cast<size_t>(first_ref.back()));
  {
    std::vector<int32_t> fill(first_ref.begin(), first_ref.end() - 1);
    for (size_t f = 0; f < map.keyframes.size(); ++f) {
      const MapKeyframe& keyframe = map.keyframes[f];
      for (int o = 0; o < keyframe.num_observations(); ++o) {
        refs[static_cast<size_t>(fill[static_cast<size_t>(keyframe.point_ids[static_cast<size_t>(o)])]++)] =
            ObservationRef{static_cast<int32_t>(f), o};
      }
    }
  }
  map.point_descriptors.resize(static_cast<size_t>(num_points) * kDescriptorSize);
  ThreadPool pool(ThreadPool::ResolveThreadCount(options.num_threads));
  pool.ParallelFor(0, static_cast<size_t>(num_points), [&](size_t i, int) {
    const int begin = first_ref[i], count = first_ref[i + 1] - begin;
    const int taken = std::min(count, options.max_medoid_candidates);
    std::vector<const uint8_t*> candidates;
    candidates.reserve(static_cast<size_t>(taken));
    for (int c = 0; c < taken; ++c) {
      const ObservationRef& ref =
          refs[static_cast<size_t>(begin + static_cast<int>(static_cast<int64_t>(c) * count / taken))];
      candidates.push_back(&map.keyframes[static_cast<size_t>(ref.keyframe)]
                                .descriptors[static_cast<size_t>(ref.observation) * kDescriptorSize]);
    }
    std::copy_n(candidates[static_cast<size_t>(MedoidOf(candidates))], kDescriptorSize,
                &map.point_descriptors[i * kDescriptorSize]);
  });
  report->seconds_descriptors = SecondsSince(start);

  // The vocabulary, trained on every observation's descriptor.
  start = Clock::now();
  std::vector<uint8_t> all_descriptors;
  for (const MapKeyframe& keyframe : map.keyframes) {
    all_descriptors.insert(all_descriptors.end(), keyframe.descriptors.begin(), keyframe.descriptors.end());
  }
  VocabularyTreeOptions vocabulary_options = options.vocabulary;
  vocabulary_options.num_threads = options.num_threads;
  RECONAR_ASSIGN_OR_RETURN(
      map.vocabulary,
      VocabularyTree::Train(all_descriptors.data(), static_cast<int>(all_descriptors.size() / kDescriptorSize),
                            vocabulary_options));
  report->seconds_vocabulary = SecondsSince(start);

  start = Clock::now();
  std::vector<std::vector<int32_t>> keyframe_words(map.keyframes.size());
  pool.ParallelFor(0, map.keyframes.size(), [&](size_t f, int) {
    const MapKeyframe& keyframe = map.keyframes[f];
    keyframe_words[f].resize(static_cast<size_t>(keyframe.num_observations()));
    for (int o = 0; o < keyframe.num_observations(); ++o) {
      keyframe_words[f][static_cast<size_t>(o)] =
          map.vocabulary.Quantize(&keyframe.descriptors[static_cast<size_t>(o) * kDescriptorSize]);
    }
  });
  RECONAR_ASSIGN_OR_RETURN(map.keyframe_index, InvertedFile::Build(map.vocabulary.num_words(), keyframe_words));
  report->seconds_index = SecondsSince(start);

  report->keyframes = static_cast<int>(map.keyframes.size());
  report->points = num_points;
  report->observations = map.num_observations();
  report->words = map.vocabulary.num_words();
  report->memory_bytes = map.memory_bytes();
  return map;
}

}  // namespace reconar
