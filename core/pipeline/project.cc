#include "core/pipeline/project.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/file_order.h"

namespace reconar {

namespace fs = std::filesystem;

std::string Project::MatchedFeaturePath(const std::string& image_name) const {
  std::error_code error;
  const std::string richer = RicherFeaturePath(image_name);
  return fs::exists(richer, error) ? richer : FeaturePath(image_name);
}

Status Project::WriteImageList(const std::vector<ProjectImage>& images) const {
  RECONAR_RETURN_IF_ERROR(CreateDirectories(FeaturesDir()));
  std::ostringstream out;
  out << "# name width height focal_px focal_source path\n";
  out.precision(10);
  for (const ProjectImage& image : images) {
    out << image.name << ' ' << image.width << ' ' << image.height << ' ' << image.focal_px << ' '
        << image.focal_source << ' ' << image.path << '\n';
  }
  return WriteFileAtomically(ImageListPath(), out.str());
}

Result<std::vector<ProjectImage>> Project::ReadImageList() const {
  auto text = ReadFileToString(ImageListPath());
  if (!text.ok()) {
    if (text.status().code() == StatusCode::kNotFound) {
      return NotFound(ImageListPath() + ": no image list; run `reconar features IMAGES --project " + root_ +
                      "` first");
    }
    return text.status();
  }
  std::vector<ProjectImage> images;
  std::istringstream in(*text);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    ProjectImage image;
    if (!(fields >> image.name >> image.width >> image.height >> image.focal_px >> image.focal_source)) {
      return FileError(StatusCode::kCorruptData, ImageListPath(), "malformed line " + std::to_string(line_number));
    }
    std::getline(fields >> std::ws, image.path);
    images.push_back(image);
  }
  return images;
}

Result<std::map<std::string, std::string>> Project::PhotoPathsByName() const {
  RECONAR_ASSIGN_OR_RETURN(const std::vector<ProjectImage> list, ReadImageList());
  std::map<std::string, std::string> path_of;
  for (const ProjectImage& image : list) path_of[image.name] = image.path;
  return path_of;
}

Result<std::vector<std::string>> CollectImagePaths(const std::vector<std::string>& arguments) {
  std::vector<std::string> paths;
  for (const std::string& argument : arguments) {
    std::error_code ec;
    if (fs::is_directory(argument, ec)) {
      std::vector<std::string> found;
      for (auto it = fs::directory_iterator(argument, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const fs::directory_entry& entry = *it;
        std::error_code type_error;
        if (!entry.is_regular_file(type_error)) continue;
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
        if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") found.push_back(entry.path().string());
      }
      if (ec) return FileError(StatusCode::kIoError, argument, "cannot list directory: " + ec.message());
      SortFileNames(&found);
      paths.insert(paths.end(), found.begin(), found.end());
    } else if (fs::exists(argument, ec)) {
      paths.push_back(argument);
    } else {
      return FileError(StatusCode::kNotFound, argument, "no such file or directory");
    }
  }
  if (paths.empty()) return InvalidArgument("no images (.jpg, .jpeg, .png) found in the given arguments");
  for (std::string& path : paths) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(path, ec);
    if (ec) return FileError(StatusCode::kIoError, path, "cannot make the path absolute: " + ec.message());
    path = absolute.lexically_normal().string();
  }
  std::set<std::string> names;
  for (const std::string& path : paths) {
    const std::string name = fs::path(path).filename().string();
    if (!names.insert(name).second) {
      return InvalidArgument(path + ": another image is also named " + name + "; image names must be unique");
    }
  }
  return paths;
}

Status RemoveFileIfPresent(const std::string& path) {
  if (::unlink(path.c_str()) == 0 || errno == ENOENT) return Status::Ok();
  return FileError(StatusCode::kIoError, path, std::string("cannot remove: ") + std::strerror(errno));
}

}  // namespace reconar
