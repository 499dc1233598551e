#include "core/sfm/tag_observations.h"

#include <cstdio>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {

Status WriteTagDetections(const std::string& path, const TagDetectionsFile& file) {
  std::string text = "# reconar tag detections v1\nfamily " + file.family + "\n";
  char buffer[64];
  for (const ImageTagObservations& image : file.images) {
    text += "image " + image.image_name + " " + std::to_string(image.tags.size()) + "\n";
    for (const TagObservation& tag : image.tags) {
      text += std::to_string(tag.tag_id);
      for (const Eigen::Vector2d& c : tag.corners) {
        std::snprintf(buffer, sizeof(buffer), " %.17g %.17g", c.x(), c.y());
        text += buffer;
      }
      text += "\n";
    }
  }
  return WriteFileAtomically(path, text);
}

Result<TagDetectionsFile> ReadTagDetections(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::string line;
  int number = 0;
  const auto corrupt = [&](const std::string& why) {
    return FileError(StatusCode::kCorruptData, path, "line " + std::to_string(number) + ": " + why);
  };
  TagDetectionsFile file;
  if (!std::getline(in, line) || line != "# reconar tag detections v1") {
    ++number;
    return corrupt("not a reconar tag detections file");
  }
  ++number;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "family") {
      if (!(fields >> file.family)) return corrupt("family without a name");
    } else if (key == "image") {
      ImageTagObservations image;
      int count = -1;
      if (!(fields >> image.image_name >> count) || count < 0) return corrupt("expected 'image NAME COUNT'");
      for (int t = 0; t < count; ++t) {
        if (!std::getline(in, line)) return corrupt("file ends inside image " + image.image_name);
        ++number;
        std::istringstream tag_fields(line);
        TagObservation tag;
        tag_fields >> tag.tag_id;
        for (Eigen::Vector2d& c : tag.corners) tag_fields >> c.x() >> c.y();
        if (!tag_fields || tag.tag_id < 0 || !(tag_fields >> std::ws).eof())
          return corrupt("expected 'ID x0 y0 ... x3 y3'");
        image.tags.push_back(tag);
      }
      file.images.push_back(std::move(image));
    } else {
      return corrupt("unknown record '" + key + "'");
    }
  }
  return file;
}

}  // namespace reconar
