#include "core/sfm/tag_layout.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace reconar {

Status TagLayout::Add(const LayoutTag& tag) {
  if (tag.id < 0) return InvalidArgument("tag id must be >= 0, got " + std::to_string(tag.id));
  if (!(tag.size > 0.0) || !std::isfinite(tag.size)) {
    return InvalidArgument("tag " + std::to_string(tag.id) + ": size must be > 0, got " + std::to_string(tag.size));
  }
  if (!tag.layout_from_tag.rotation.allFinite() || !tag.layout_from_tag.translation.allFinite()) {
    return InvalidArgument("tag " + std::to_string(tag.id) + ": pose is not finite");
  }
  const auto it =
      std::lower_bound(tags_.begin(), tags_.end(), tag.id, [](const LayoutTag& a, int id) { return a.id < id; });
  if (it != tags_.end() && it->id == tag.id) {
    return InvalidArgument("tag " + std::to_string(tag.id) + " is listed twice");
  }
  tags_.insert(it, tag);
  return Status::Ok();
}

const LayoutTag* TagLayout::Find(int id) const {
  const auto it =
      std::lower_bound(tags_.begin(), tags_.end(), id, [](const LayoutTag& a, int key) { return a.id < key; });
  return it != tags_.end() && it->id == id ? &*it : nullptr;
}

bool TagLayout::IsPlanar() const {
  for (const LayoutTag& tag : tags_) {
    if (std::abs(tag.layout_from_tag.translation.z()) > 1e-9) return false;
    if ((tag.layout_from_tag.rotation.col(2) - Eigen::Vector3d::UnitZ()).norm() > 1e-9) return false;
  }
  return true;
}

Result<TagLayout> ParseTagLayout(const std::string& text, const std::string& name_for_errors) {
  TagLayout layout;
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string where = name_for_errors + ":" + std::to_string(line_number) + ": ";
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string token; fields >> token;) tokens.push_back(token);
    if (tokens.empty()) continue;
    std::vector<double> values;
    for (const std::string& token : tokens) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
        return CorruptData(where + "'" + token + "' is not a finite number");
      }
      values.push_back(value);
    }
    if (values.size() != 4 && values.size() != 5 && values.size() != 9) {
      return CorruptData(where +
                         "expected 'id size x y z qw qx qy qz' (9 fields) or 'id size cx cy [angle_deg]' "
                         "(4 or 5 fields), got " +
                         std::to_string(values.size()) + " fields");
    }
    if (values[0] != std::floor(values[0]) || values[0] < 0 || values[0] > std::numeric_limits<int>::max()) {
      return CorruptData(where + "tag id must be a non-negative integer, got " + tokens[0]);
    }
    LayoutTag tag;
    tag.id = static_cast<int>(values[0]);
    tag.size = values[1];
    if (values.size() == 9) {
      tag.layout_from_tag.translation = Eigen::Vector3d(values[2], values[3], values[4]);
      const Eigen::Quaterniond q(values[5], values[6], values[7], values[8]);
      if (!(q.norm() > 1e-9)) return CorruptData(where + "the quaternion is zero");
      tag.layout_from_tag.rotation = q.normalized().toRotationMatrix();
    } else {
      tag.layout_from_tag.translation = Eigen::Vector3d(values[2], values[3], 0.0);
      const double angle = values.size() == 5 ? values[4] * M_PI / 180.0 : 0.0;
      tag.layout_from_tag.rotation = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    const Status added = layout.Add(tag);
    if (!added.ok()) return InvalidArgument(where + added.message());
  }
  if (layout.empty()) return InvalidArgument(name_for_errors + ": the layout lists no tags");
  return layout;
}

Result<TagLayout> ReadTagLayout(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return FileError(StatusCode::kNotFound, path, "cannot open the tag layout file");
  std::ostringstream content;
  content << file.rdbuf();
  if (file.bad()) return FileError(StatusCode::kIoError, path, "read failed");
  return ParseTagLayout(content.str(), path);
}

std::string FormatTagLayout(const std::vector<LayoutTag>& tags) {
  std::string text = "# reconar tag layout: id size x y z qw qx qy qz (world_from_tag, metres)\n";
  char line[320];
  for (const LayoutTag& tag : tags) {
    const Eigen::Quaterniond q(tag.layout_from_tag.rotation);
    const Eigen::Vector3d& t = tag.layout_from_tag.translation;
    std::snprintf(line, sizeof(line), "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", tag.id, tag.size, t.x(),
                  t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
    text += line;
  }
  return text;
}

}  // namespace reconar
