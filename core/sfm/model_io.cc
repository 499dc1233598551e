#include "core/sfm/model_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <string_view>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/base/number_format.h"
#include "core/base/text_fields.h"

namespace reconar {

namespace {

// COLMAP puts the centre of the top-left pixel at (0.5, 0.5), we put it at (0, 0).
constexpr double kColmapPixelOffset = 0.5;

// ---------------------------------------------------------------------------------------------
// What the writers export.

bool IsRegisteredImage(const Reconstruction& reconstruction, int image_id) {
  return image_id >= 0 && image_id < static_cast<int>(reconstruction.images.size()) &&
         reconstruction.images[image_id].registered;
}

bool IsExportedPoint(const Reconstruction& reconstruction, int point_id) {
  if (point_id < 0 || point_id >= static_cast<int>(reconstruction.points.size())) return false;
  const SfmPoint& point = reconstruction.points[point_id];
  if (point.deleted) return false;
  for (const TrackElement& element : point.track) {
    if (IsRegisteredImage(reconstruction, element.image_id)) return true;
  }
  return false;
}

// Indices that the writers follow must be in range: a broken model is the caller's bug, but it
// is reported instead of being written as a file that other tools would misread.
Status CheckIndices(const Reconstruction& reconstruction) {
  const int num_cameras = static_cast<int>(reconstruction.cameras.size());
  const int num_images = static_cast<int>(reconstruction.images.size());
  const int num_points = static_cast<int>(reconstruction.points.size());
  for (int i = 0; i < num_images; ++i) {
    const SfmImage& image = reconstruction.images[i];
    const std::string where = "reconstruction: image " + std::to_string(i) + " (" + image.name + ")";
    if (image.camera_id < 0 || image.camera_id >= num_cameras) {
      return InvalidArgument(where + ": camera_id " + std::to_string(image.camera_id) + " out of range");
    }
    if (image.point3d_ids.size() != image.keypoints.size()) {
      return InvalidArgument(where + ": point3d_ids and keypoints differ in size");
    }
    for (const int point_id : image.point3d_ids) {
      if (point_id < -1 || point_id >= num_points) {
        return InvalidArgument(where + ": point3d_id " + std::to_string(point_id) + " out of range");
      }
    }
    if (image.registered && (image.name.empty() || image.name.find_first_of(" \t\r\n") != std::string::npos)) {
      return InvalidArgument(where + ": image names must be non-empty without white space");
    }
  }
  for (int i = 0; i < num_points; ++i) {
    for (const TrackElement& element : reconstruction.points[i].track) {
      const bool valid = element.image_id >= 0 && element.image_id < num_images && element.keypoint_id >= 0 &&
                         element.keypoint_id < static_cast<int>(reconstruction.images[element.image_id].keypoints.size());
      if (!valid) {
        return InvalidArgument("reconstruction: point " + std::to_string(i) + " has track element (" +
                               std::to_string(element.image_id) + ", " + std::to_string(element.keypoint_id) +
                               ") out of range");
      }
    }
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// Text output.

void AppendNumbers(std::string* out, std::initializer_list<double> values) {
  for (const double value : values) {
    if (!out->empty() && out->back() != '\n') out->push_back(' ');
    AppendShortest(out, value);
  }
}

// The means in COLMAP's header comments, printed as its stream does (precision 17).
std::string FormatMean(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

void WriteString(std::FILE* file, const std::string& text) { std::fwrite(text.data(), 1, text.size(), file); }

// ---------------------------------------------------------------------------------------------
// Text input.

bool ParseNumber(std::string_view text, double* value) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size() && std::isfinite(*value);
}

bool ParseNumber(std::string_view text, int64_t* value) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

// Walks a text file line by line, splitting each line into white-space separated fields, and
// turns problems into "path:line: reason".
class LineReader {
 public:
  LineReader(std::string path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  // Advances to the next line; false at the end of the file.
  bool NextLine() {
    if (position_ >= text_.size()) return false;
    size_t end = text_.find('\n', position_);
    if (end == std::string::npos) end = text_.size();
    const std::string_view line(text_.data() + position_, end - position_);
    position_ = end + 1;
    ++line_number_;
    SplitFields(line, &fields_);
    return true;
  }

  // Advances to the next line that is neither blank nor a '#' comment.
  bool NextDataLine() {
    while (NextLine()) {
      if (!fields_.empty() && fields_[0][0] != '#') return true;
    }
    return false;
  }

  size_t size() const { return fields_.size(); }
  std::string_view field(size_t i) const { return fields_[i]; }
  int line_number() const { return line_number_; }

  Status Error(const std::string& reason) const {
    return CorruptData(path_ + ":" + std::to_string(line_number_) + ": " + reason);
  }

  template <typename T>
  Status Read(size_t i, const char* what, T* value) const {
    if (i >= fields_.size()) return Error(std::string("missing ") + what);
    if (!ParseNumber(fields_[i], value)) {
      return Error(std::string("bad ") + what + " '" + std::string(fields_[i]) + "'");
    }
    return Status::Ok();
  }

  // An integer id that must fit an int.
  Status ReadId(size_t i, const char* what, int* value) const {
    int64_t wide = 0;
    RECONAR_RETURN_IF_ERROR(Read(i, what, &wide));
    if (wide < -1 || wide > INT32_MAX) return Error(std::string(what) + " out of range");
    *value = static_cast<int>(wide);
    return Status::Ok();
  }

 private:
  std::string path_;
  std::string text_;
  size_t position_ = 0;
  int line_number_ = 0;
  std::vector<std::string_view> fields_;
};

Result<LineReader> OpenText(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return LineReader(path, std::move(text));
}

std::string JoinPath(const std::string& dir, const std::string& name) {
  if (dir.empty() || dir.back() == '/') return dir + name;
  return dir + "/" + name;
}

// ---------------------------------------------------------------------------------------------
// COLMAP writers.

Status WriteColmapCameras(const Reconstruction& reconstruction, const std::string& path) {
  return WriteFileAtomically(path, [&](std::FILE* file) {
    WriteString(file,
                "# Camera list with one line of data per camera:\n"
                "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                "# Number of cameras: " +
                    std::to_string(reconstruction.cameras.size()) + "\n");
    std::string line;
    for (size_t i = 0; i < reconstruction.cameras.size(); ++i) {
      const SfmCamera& camera = reconstruction.cameras[i];
      const bool square = camera.aspect == 1.0;
      line = std::to_string(i + 1) + (square ? " RADIAL " : " OPENCV ") + std::to_string(camera.width) + " " +
             std::to_string(camera.height);
      if (square) {
        AppendNumbers(&line, {camera.focal, camera.cx + kColmapPixelOffset, camera.cy + kColmapPixelOffset,
                              camera.k1, camera.k2});
      } else {  // fx, fy, cx, cy, k1, k2, p1, p2
        AppendNumbers(&line, {camera.focal, camera.aspect * camera.focal, camera.cx + kColmapPixelOffset,
                              camera.cy + kColmapPixelOffset, camera.k1, camera.k2, 0.0, 0.0});
      }
      line += '\n';
      WriteString(file, line);
    }
    return Status::Ok();
  });
}

Status WriteColmapImages(const Reconstruction& reconstruction, const std::string& path) {
  int num_registered = 0;
  int num_observations = 0;
  for (const SfmImage& image : reconstruction.images) {
    if (!image.registered) continue;
    ++num_registered;
    for (const int point_id : image.point3d_ids) num_observations += IsExportedPoint(reconstruction, point_id) ? 1 : 0;
  }
  const double mean_observations = num_registered > 0 ? static_cast<double>(num_observations) / num_registered : 0.0;
  return WriteFileAtomically(path, [&](std::FILE* file) {
    WriteString(file,
                "# Image list with two lines of data per image:\n"
                "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                "# Number of images: " +
                    std::to_string(num_registered) +
                    ", mean observations per image: " + FormatMean(mean_observations) + "\n");
    std::string line;
    for (size_t i = 0; i < reconstruction.images.size(); ++i) {
      const SfmImage& image = reconstruction.images[i];
      if (!image.registered) continue;
      Eigen::Quaterniond q(image.cam_from_world.rotation);
      q.normalize();
      if (q.w() < 0) q.coeffs() = -q.coeffs();
      const Eigen::Vector3d& t = image.cam_from_world.translation;
      line = std::to_string(i + 1);
      AppendNumbers(&line, {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()});
      line += " " + std::to_string(image.camera_id + 1) + " " + image.name + "\n";
      for (size_t k = 0; k < image.keypoints.size(); ++k) {
        const int point_id = image.point3d_ids[k];
        if (k > 0) line += ' ';
        AppendShortest(&line, image.keypoints[k].x() + kColmapPixelOffset);
        line += ' ';
        AppendShortest(&line, image.keypoints[k].y() + kColmapPixelOffset);
        line += ' ';
        line += IsExportedPoint(reconstruction, point_id) ? std::to_string(point_id + 1) : "-1";
      }
      line += '\n';
      WriteString(file, line);
    }
    return Status::Ok();
  });
}

Status WriteColmapPoints(const Reconstruction& reconstruction, const std::string& path) {
  int num_points = 0;
  int num_elements = 0;
  for (size_t i = 0; i < reconstruction.points.size(); ++i) {
    if (!IsExportedPoint(reconstruction, static_cast<int>(i))) continue;
    ++num_points;
    for (const TrackElement& element : reconstruction.points[i].track) {
      num_elements += IsRegisteredImage(reconstruction, element.image_id) ? 1 : 0;
    }
  }
  const double mean_track_length = num_points > 0 ? static_cast<double>(num_elements) / num_points : 0.0;
  return WriteFileAtomically(path, [&](std::FILE* file) {
    WriteString(file,
                "# 3D point list with one line of data per point:\n"
                "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
                "# Number of points: " +
                    std::to_string(num_points) + ", mean track length: " + FormatMean(mean_track_length) + "\n");
    std::string line;
    for (size_t i = 0; i < reconstruction.points.size(); ++i) {
      if (!IsExportedPoint(reconstruction, static_cast<int>(i))) continue;
      const SfmPoint& point = reconstruction.points[i];
      line = std::to_string(i + 1);
      AppendNumbers(&line, {point.position.x(), point.position.y(), point.position.z()});
      for (const uint8_t c : point.color) line += " " + std::to_string(c);
      line += ' ';
      AppendShortest(&line, point.error);
      for (const TrackElement& element : point.track) {
        if (!IsRegisteredImage(reconstruction, element.image_id)) continue;
        line += " " + std::to_string(element.image_id + 1) + " " + std::to_string(element.keypoint_id);
      }
      line += '\n';
      WriteString(file, line);
    }
    return Status::Ok();
  });
}

// ---------------------------------------------------------------------------------------------
// COLMAP readers. Each returns its entities sorted by id, with the id alongside.

template <typename T>
struct WithId {
  int id = 0;
  int line_number = 0;
  T value;
};

template <typename T>
void SortById(std::vector<WithId<T>>* entries) {
  std::stable_sort(entries->begin(), entries->end(), [](const WithId<T>& a, const WithId<T>& b) { return a.id < b.id; });
}

Result<std::vector<WithId<SfmCamera>>> ReadColmapCameras(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(LineReader in, OpenText(path));
  std::vector<WithId<SfmCamera>> cameras;
  while (in.NextDataLine()) {
    WithId<SfmCamera> entry;
    entry.line_number = in.line_number();
    SfmCamera& camera = entry.value;
    RECONAR_RETURN_IF_ERROR(in.ReadId(0, "CAMERA_ID", &entry.id));
    if (in.size() < 2) return in.Error("missing MODEL");
    const std::string model(in.field(1));
    RECONAR_RETURN_IF_ERROR(in.ReadId(2, "WIDTH", &camera.width));
    RECONAR_RETURN_IF_ERROR(in.ReadId(3, "HEIGHT", &camera.height));
    if (camera.width <= 0 || camera.height <= 0) return in.Error("image size must be positive");

    const std::map<std::string, size_t> num_params = {
        {"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4}, {"RADIAL", 5}, {"OPENCV", 8}};
    const auto found = num_params.find(model);
    if (found == num_params.end()) {
      return in.Error("camera model " + model +
                      " is not supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV without tangential terms)");
    }
    if (in.size() != 4 + found->second) {
      return in.Error(model + " needs " + std::to_string(found->second) + " parameters, got " +
                      std::to_string(in.size() - 4));
    }
    double params[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < found->second; ++i) RECONAR_RETURN_IF_ERROR(in.Read(4 + i, "camera parameter", &params[i]));
    if (model == "PINHOLE" || model == "OPENCV") {
      if (params[6] != 0.0 || params[7] != 0.0) {
        return in.Error("OPENCV tangential distortion (p1, p2) is not supported; undistort the images first");
      }
      camera.focal = params[0];
      camera.aspect = params[1] / params[0];
      camera.cx = params[2];
      camera.cy = params[3];
      camera.k1 = params[4];
      camera.k2 = params[5];
    } else {
      camera.focal = params[0];
      camera.cx = params[1];
      camera.cy = params[2];
      camera.k1 = params[3];
      camera.k2 = params[4];
    }
    camera.cx -= kColmapPixelOffset;
    camera.cy -= kColmapPixelOffset;
    if (!(camera.focal > 0)) return in.Error("focal length must be positive");
    cameras.push_back(std::move(entry));
  }
  SortById(&cameras);
  return cameras;
}

// An image as images.txt gives it: camera and points by COLMAP id, to be resolved to indices.
struct ColmapImage {
  SfmImage image;
  int camera_id = 0;
  std::vector<int> point3d_ids;
  int points2d_line_number = 0;
};

Result<std::vector<WithId<ColmapImage>>> ReadColmapImages(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(LineReader in, OpenText(path));
  std::vector<WithId<ColmapImage>> images;
  while (in.NextDataLine()) {
    WithId<ColmapImage> entry;
    entry.line_number = in.line_number();
    SfmImage& image = entry.value.image;
    if (in.size() != 10) return in.Error("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    RECONAR_RETURN_IF_ERROR(in.ReadId(0, "IMAGE_ID", &entry.id));
    double q[4];
    for (int i = 0; i < 4; ++i) RECONAR_RETURN_IF_ERROR(in.Read(1 + i, "quaternion", &q[i]));
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    if (!(rotation.norm() > 1e-6)) return in.Error("quaternion of zero length");
    image.cam_from_world.rotation = rotation.normalized().toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
      RECONAR_RETURN_IF_ERROR(in.Read(5 + i, "translation", &image.cam_from_world.translation[i]));
    }
    RECONAR_RETURN_IF_ERROR(in.ReadId(8, "CAMERA_ID", &entry.value.camera_id));
    image.name = std::string(in.field(9));
    image.registered = true;

    // The POINTS2D line follows unconditionally; it is empty for an image without keypoints.
    if (!in.NextLine()) return in.Error("missing POINTS2D line after the image line");
    entry.value.points2d_line_number = in.line_number();
    if (in.size() % 3 != 0) return in.Error("POINTS2D must be triples X Y POINT3D_ID");
    for (size_t i = 0; i < in.size(); i += 3) {
      Eigen::Vector2d xy;
      int point3d_id = -1;
      RECONAR_RETURN_IF_ERROR(in.Read(i, "X", &xy.x()));
      RECONAR_RETURN_IF_ERROR(in.Read(i + 1, "Y", &xy.y()));
      int64_t wide_id = 0;
      RECONAR_RETURN_IF_ERROR(in.Read(i + 2, "POINT3D_ID", &wide_id));
      if (wide_id != -1) {
        if (wide_id < 0 || wide_id > INT32_MAX) return in.Error("POINT3D_ID out of range");
        point3d_id = static_cast<int>(wide_id);
      }
      image.keypoints.push_back(xy - Eigen::Vector2d::Constant(kColmapPixelOffset));
      entry.value.point3d_ids.push_back(point3d_id);
    }
    images.push_back(std::move(entry));
  }
  SortById(&images);
  return images;
}

// A point as points3D.txt gives it: track image ids are COLMAP ids.
Result<std::vector<WithId<SfmPoint>>> ReadColmapPoints(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(LineReader in, OpenText(path));
  std::vector<WithId<SfmPoint>> points;
  while (in.NextDataLine()) {
    WithId<SfmPoint> entry;
    entry.line_number = in.line_number();
    SfmPoint& point = entry.value;
    if (in.size() < 8 || (in.size() - 8) % 2 != 0) {
      return in.Error("expected POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID, POINT2D_IDX)");
    }
    int64_t id = 0;
    RECONAR_RETURN_IF_ERROR(in.Read(0, "POINT3D_ID", &id));
    if (id < 0 || id > INT32_MAX) return in.Error("POINT3D_ID out of range");
    entry.id = static_cast<int>(id);
    for (int i = 0; i < 3; ++i) RECONAR_RETURN_IF_ERROR(in.Read(1 + i, "coordinate", &point.position[i]));
    for (int i = 0; i < 3; ++i) {
      int64_t c = 0;
      RECONAR_RETURN_IF_ERROR(in.Read(4 + i, "colour", &c));
      if (c < 0 || c > 255) return in.Error("colour out of 0..255");
      point.color[i] = static_cast<uint8_t>(c);
    }
    RECONAR_RETURN_IF_ERROR(in.Read(7, "ERROR", &point.error));
    for (size_t i = 8; i < in.size(); i += 2) {
      TrackElement element;
      RECONAR_RETURN_IF_ERROR(in.ReadId(i, "IMAGE_ID", &element.image_id));
      RECONAR_RETURN_IF_ERROR(in.ReadId(i + 1, "POINT2D_IDX", &element.keypoint_id));
      point.track.push_back(element);
    }
    points.push_back(std::move(entry));
  }
  SortById(&points);
  return points;
}

using IdIndex = std::map<int, int>;  // COLMAP id -> index

// Index of each id in entries sorted by id; the first duplicate is an error at its line.
template <typename T>
Result<IdIndex> IndexById(const std::vector<WithId<T>>& entries, const std::string& path,
                                     const char* what) {
  IdIndex index;
  for (size_t i = 0; i < entries.size(); ++i) {
    if (!index.emplace(entries[i].id, static_cast<int>(i)).second) {
      return CorruptData(path + ":" + std::to_string(entries[i].line_number) + ": duplicate " + what + " " +
                         std::to_string(entries[i].id));
    }
  }
  return index;
}

std::string PlaceError(const std::string& path, int line_number, const std::string& reason) {
  return path + ":" + std::to_string(line_number) + ": " + reason;
}

// ---------------------------------------------------------------------------------------------
// Binary output.

void AppendLittleEndian32(std::string* out, uint32_t bits) {
  for (int shift = 0; shift < 32; shift += 8) out->push_back(static_cast<char>((bits >> shift) & 0xff));
}

}  // namespace

Status WriteColmapTextModel(const Reconstruction& reconstruction, const std::string& dir) {
  RECONAR_RETURN_IF_ERROR(CheckIndices(reconstruction));
  RECONAR_RETURN_IF_ERROR(CreateDirectories(dir));
  RECONAR_RETURN_IF_ERROR(WriteColmapCameras(reconstruction, JoinPath(dir, "cameras.txt")));
  RECONAR_RETURN_IF_ERROR(WriteColmapImages(reconstruction, JoinPath(dir, "images.txt")));
  return WriteColmapPoints(reconstruction, JoinPath(dir, "points3D.txt"));
}

Result<Reconstruction> ReadColmapTextModel(const std::string& dir) {
  const std::string cameras_path = JoinPath(dir, "cameras.txt");
  const std::string images_path = JoinPath(dir, "images.txt");
  const std::string points_path = JoinPath(dir, "points3D.txt");
  RECONAR_ASSIGN_OR_RETURN(std::vector<WithId<SfmCamera>> cameras, ReadColmapCameras(cameras_path));
  RECONAR_ASSIGN_OR_RETURN(std::vector<WithId<ColmapImage>> images, ReadColmapImages(images_path));
  RECONAR_ASSIGN_OR_RETURN(std::vector<WithId<SfmPoint>> points, ReadColmapPoints(points_path));
  RECONAR_ASSIGN_OR_RETURN(const IdIndex camera_index, IndexById(cameras, cameras_path, "CAMERA_ID"));
  RECONAR_ASSIGN_OR_RETURN(const IdIndex image_index, IndexById(images, images_path, "IMAGE_ID"));
  RECONAR_ASSIGN_OR_RETURN(const IdIndex point_index, IndexById(points, points_path, "POINT3D_ID"));

  Reconstruction reconstruction;
  for (WithId<SfmCamera>& camera : cameras) reconstruction.cameras.push_back(camera.value);

  for (WithId<ColmapImage>& entry : images) {
    SfmImage& image = entry.value.image;
    const auto camera = camera_index.find(entry.value.camera_id);
    if (camera == camera_index.end()) {
      return CorruptData(PlaceError(images_path, entry.line_number,
                                    "CAMERA_ID " + std::to_string(entry.value.camera_id) + " not in cameras.txt"));
    }
    image.camera_id = camera->second;
    for (const int id : entry.value.point3d_ids) {
      int index = -1;
      if (id != -1) {
        const auto point = point_index.find(id);
        if (point == point_index.end()) {
          return CorruptData(PlaceError(images_path, entry.value.points2d_line_number,
                                        "POINT3D_ID " + std::to_string(id) + " not in points3D.txt"));
        }
        index = point->second;
      }
      image.point3d_ids.push_back(index);
    }
    reconstruction.images.push_back(std::move(image));
  }

  for (size_t p = 0; p < points.size(); ++p) {
    SfmPoint& point = points[p].value;
    for (TrackElement& element : point.track) {
      const std::string where = "track element (" + std::to_string(element.image_id) + ", " +
                                std::to_string(element.keypoint_id) + ")";
      const auto image = image_index.find(element.image_id);
      if (image == image_index.end()) {
        return CorruptData(PlaceError(points_path, points[p].line_number, where + ": IMAGE_ID not in images.txt"));
      }
      element.image_id = image->second;
      const std::vector<int>& ids = reconstruction.images[element.image_id].point3d_ids;
      if (element.keypoint_id < 0 || element.keypoint_id >= static_cast<int>(ids.size())) {
        return CorruptData(PlaceError(points_path, points[p].line_number, where + ": POINT2D_IDX out of range"));
      }
      if (ids[element.keypoint_id] != static_cast<int>(p)) {
        return CorruptData(PlaceError(points_path, points[p].line_number,
                                      where + ": images.txt gives that keypoint another POINT3D_ID"));
      }
    }
    reconstruction.points.push_back(std::move(point));
  }
  return reconstruction;
}

Status WriteBundlerModel(const Reconstruction& reconstruction, const std::string& bundle_out_path,
                         const std::string& list_txt_path, const std::vector<std::string>& image_paths) {
  RECONAR_RETURN_IF_ERROR(CheckIndices(reconstruction));
  if (!image_paths.empty() && image_paths.size() != reconstruction.images.size()) {
    return InvalidArgument(list_txt_path + ": " + std::to_string(image_paths.size()) + " image paths for " +
                           std::to_string(reconstruction.images.size()) + " images");
  }
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(list_txt_path, [&](std::FILE* file) {
    for (size_t i = 0; i < reconstruction.images.size(); ++i) {
      WriteString(file, (image_paths.empty() ? reconstruction.images[i].name : image_paths[i]) + "\n");
    }
    return Status::Ok();
  }));

  // Bundler's camera frame: x right, y up, looking down -z.
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  int num_points = 0;
  for (size_t i = 0; i < reconstruction.points.size(); ++i) {
    num_points += IsExportedPoint(reconstruction, static_cast<int>(i)) ? 1 : 0;
  }
  return WriteFileAtomically(bundle_out_path, [&](std::FILE* file) {
    WriteString(file, "# Bundle file v0.3\n" + std::to_string(reconstruction.images.size()) + " " +
                          std::to_string(num_points) + "\n");
    std::string text;
    for (const SfmImage& image : reconstruction.images) {
      if (!image.registered) {
        WriteString(file, "0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n");
        continue;
      }
      const SfmCamera& camera = reconstruction.cameras[image.camera_id];
      const Eigen::Matrix3d R = flip * image.cam_from_world.rotation;
      const Eigen::Vector3d t = flip * image.cam_from_world.translation;
      text.clear();
      AppendNumbers(&text, {camera.focal, camera.k1, camera.k2});
      for (int r = 0; r < 3; ++r) {
        text += '\n';
        AppendNumbers(&text, {R(r, 0), R(r, 1), R(r, 2)});
      }
      text += '\n';
      AppendNumbers(&text, {t.x(), t.y(), t.z()});
      text += '\n';
      WriteString(file, text);
    }
    for (size_t i = 0; i < reconstruction.points.size(); ++i) {
      if (!IsExportedPoint(reconstruction, static_cast<int>(i))) continue;
      const SfmPoint& point = reconstruction.points[i];
      text.clear();
      AppendNumbers(&text, {point.position.x(), point.position.y(), point.position.z()});
      text += "\n" + std::to_string(point.color[0]) + " " + std::to_string(point.color[1]) + " " +
              std::to_string(point.color[2]) + "\n";
      std::string views;
      int num_views = 0;
      for (const TrackElement& element : point.track) {
        if (!IsRegisteredImage(reconstruction, element.image_id)) continue;
        const SfmImage& image = reconstruction.images[element.image_id];
        const SfmCamera& camera = reconstruction.cameras[image.camera_id];
        const Eigen::Vector2d& key = image.keypoints[element.keypoint_id];
        views += " " + std::to_string(element.image_id) + " " + std::to_string(element.keypoint_id) + " ";
        AppendShortest(&views, key.x() - 0.5 * (camera.width - 1));
        views += ' ';
        AppendShortest(&views, 0.5 * (camera.height - 1) - key.y());
        ++num_views;
      }
      text += std::to_string(num_views) + views + "\n";
      WriteString(file, text);
    }
    return Status::Ok();
  });
}

Status WritePointsPly(const Reconstruction& reconstruction, const std::string& path) {
  int num_points = 0;
  for (size_t i = 0; i < reconstruction.points.size(); ++i) {
    num_points += IsExportedPoint(reconstruction, static_cast<int>(i)) ? 1 : 0;
  }
  std::string content =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "element vertex " +
      std::to_string(num_points) +
      "\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "end_header\n";
  content.reserve(content.size() + 15 * static_cast<size_t>(num_points));
  for (size_t i = 0; i < reconstruction.points.size(); ++i) {
    if (!IsExportedPoint(reconstruction, static_cast<int>(i))) continue;
    const SfmPoint& point = reconstruction.points[i];
    for (int axis = 0; axis < 3; ++axis) {
      const float value = static_cast<float>(point.position[axis]);
      uint32_t bits;
      std::memcpy(&bits, &value, sizeof(bits));
      AppendLittleEndian32(&content, bits);
    }
    for (const uint8_t c : point.color) content.push_back(static_cast<char>(c));
  }
  return WriteFileAtomically(path, content);
}

}  // namespace reconar
