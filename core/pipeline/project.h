#pragma once
// A project folder: features/ (one .rfeat per image plus images.txt, and a .more.rfeat for each
// photo the match stage extracted again), matches/ (matches.txt, report.json),
// sparse/ (the sparse model, see sfm_stage.h), map/ (the localisation map, map_stage.h) and report.json.
// images.txt lists, one image per line, "name width height focal_px focal_source path"; names are
// unique within a project and key every other file.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

// The memory budget of every stage and command unless one is given (`--memory-budget`): it suits a
// 4 GB board, with room for the OS, a display and the AR viewer.
inline constexpr size_t kDefaultMemoryBudgetBytes = 2560ull << 20;

struct ProjectImage {
  std::string name;   // file name, e.g. "0004.jpg"
  std::string path;   // absolute (CollectImagePaths), so that the project works from any directory
  int width = 0;      // after EXIF orientation
  int height = 0;
  double focal_px = 0;
  std::string focal_source;  // "exif-35mm", "exif-sensor-table" or "default"
};

class Project {
 public:
  explicit Project(std::string root) : root_(std::move(root)) {}
  const std::string& root() const { return root_; }
  std::string FeaturesDir() const { return root_ + "/features"; }
  std::string MatchesDir() const { return root_ + "/matches"; }
  std::string ImageListPath() const { return FeaturesDir() + "/images.txt"; }
  // The feature stage's features of a photo.
  std::string FeaturePath(const std::string& image_name) const { return FeaturesDir() + "/" + image_name + ".rfeat"; }
  // A poorly matched photo's features extracted again by the match stage at a lower contrast
  // threshold (match_stage.h), when it did so.
  std::string RicherFeaturePath(const std::string& image_name) const {
    return FeaturesDir() + "/" + image_name + ".more.rfeat";
  }
  // The features the project's matches index: the richer ones where they exist.
  std::string MatchedFeaturePath(const std::string& image_name) const;
  std::string MatchesPath() const { return MatchesDir() + "/matches.txt"; }
  std::string SparseDir() const { return root_ + "/sparse"; }
  std::string ReportPath() const { return root_ + "/report.json"; }
  std::string TagDetectionsPath() const { return root_ + "/tags/detections.txt"; }  // core/sfm/tag_observations.h
  std::string TagsJsonPath() const { return root_ + "/tags.json"; }  // core/sfm/tag_registration.h
  // The registered tags as a core/sfm/tag_layout.h layout (world_from_tag per id), for `track --layout`.
  std::string TagLayoutPath() const { return root_ + "/tags.layout"; }
  std::string DensePointsPath() const { return root_ + "/dense/points.ply"; }
  std::string MeshDir() const { return root_ + "/mesh"; }
  std::string MapDir() const { return root_ + "/map"; }
  std::string LiveDir() const { return root_ + "/live"; }         // the capture's live model (live_reconstruction.h)
  std::string MapPath() const { return MapDir() + "/map.rmap"; }  // core/sfm/localization_map.h

  Status WriteImageList(const std::vector<ProjectImage>& images) const;
  Result<std::vector<ProjectImage>> ReadImageList() const;
  // The image list as name -> path.
  Result<std::map<std::string, std::string>> PhotoPathsByName() const;

 private:
  std::string root_;
};

// Expands arguments into image files: a directory contributes its .jpg/.jpeg/.png files (any case,
// in name order with numbers by value: FileNameLess), a file is taken as is. NotFound for a missing
// argument; InvalidArgument when two images share a file name or nothing is left. The paths come
// back absolute and normalised.
Result<std::vector<std::string>> CollectImagePaths(const std::vector<std::string>& arguments);

// Removes a file when it exists; IoError naming the file when it cannot be removed.
Status RemoveFileIfPresent(const std::string& path);

}  // namespace reconar
