// reconar tags: a printable sheet of AprilTags whose detection border measures exactly --size, or
// the tags found in photos (as the tags stage of `reconar reconstruct` finds them).
#include <cstdio>
#include <string>
#include <vector>

#include "core/base/json_writer.h"
#include "core/pipeline/project.h"
#include "tools/commands.h"
#include "tracker/photo_tags.h"
#include "tracker/tag_detector.h"
#include "tracker/tag_sheet.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar tags --ids LIST --size METRES --out FILE.{svg,pdf} [options]\n"
    "       reconar tags IMAGES_DIR|IMAGE... [--family F] [--threads N] [--json]\n"
    "\n"
    "Writes a printable sheet of AprilTags. The tag size is the edge of the detection border (the\n"
    "black square of tag36h11: what `--tag-size` means in `reconar track`). Print at 100 %\n"
    "(no fit-to-page) and check the 100 mm scale bar. SVG writes one file per page (FILE, FILE-2, ...),\n"
    "PDF one file with a page each.\n"
    "  --family F        tag family (default tag36h11; also tag25h9, tag16h5, tagStandard41h12, ...)\n"
    "  --ids LIST        ids, e.g. 0-3 or 0,5,7-9\n"
    "  --size METRES     tag edge, e.g. 0.16\n"
    "  --paper NAME      a4 (default), a3, letter, or WIDTHxHEIGHT in mm (e.g. 300x400)\n"
    "  --margin MM       page margin (default 10)\n"
    "  --out FILE        .svg or .pdf\n"
    "  --json            print {\"family\", \"ids\", \"size_mm\", \"files\"} on stdout\n"
    "\n"
    "With photos instead, prints the tags found in each (searched as `reconar reconstruct` does),\n"
    "one line per photo, or with --json one JSON object per photo:\n"
    "  {\"image\": NAME, \"width\": W, \"height\": H, \"tags\": [{\"id\": N, \"family\": F,\n"
    "   \"hamming\": BITS, \"decision_margin\": M, \"corners\": [[x,y] x4], \"center\": [x,y]}]}\n"
    "Corners are in libapriltag's order (bottom-left, bottom-right, top-right, top-left of the\n"
    "upright tag), in pixels of the upright photo with the centre of the top-left pixel at (0, 0)\n"
    "(the convention of intrinsics files). An id printed twice in a photo is listed twice here;\n"
    "`reconar reconstruct` drops both.\n"
    "  --threads N       worker threads (default: one per core)\n";

Result<std::vector<int>> ParseIds(const std::string& text) {
  std::vector<int> ids;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t comma = text.find(',', pos);
    const std::string item = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    int first = 0;
    int last = 0;
    char extra = 0;
    if (std::sscanf(item.c_str(), "%d-%d%c", &first, &last, &extra) == 2) {
    } else if (std::sscanf(item.c_str(), "%d%c", &first, &extra) == 1) {
      last = first;
    } else {
      return InvalidArgument("--ids: '" + item + "' is not an id or a range like 0-3");
    }
    if (first < 0 || last < first) return InvalidArgument("--ids: '" + item + "' is not an increasing range");
    for (int id = first; id <= last; ++id) ids.push_back(id);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return ids;
}

std::string PhotoJson(const PhotoDetections& photo, const char* family) {
  JsonWriter json;
  json.BeginObject().Key("image").String(photo.image_name).Key("width").Int(photo.width);
  json.Key("height").Int(photo.height).Key("tags").BeginArray();
  for (const TagDetection& tag : photo.detections) {
    json.BeginObject().Key("id").Int(tag.id).Key("family").String(family).Key("hamming").Int(tag.hamming);
    json.Key("decision_margin").Double(tag.decision_margin).Key("corners").BeginArray();
    for (const Eigen::Vector2d& corner : tag.corners) {
      json.BeginArray().Double(corner.x()).Double(corner.y()).EndArray();
    }
    json.EndArray().Key("center").BeginArray().Double(tag.center.x()).Double(tag.center.y()).EndArray();
    json.EndObject();
  }
  json.EndArray().EndObject();
  return json.str();
}

// A sheet (--ids, --size and --out, no photo) or photos (none of those).
bool IsSheet(const Args& args) { return args.Has("ids") || args.Has("size") || args.Has("out"); }
bool IsRightUsage(const Args& args) {
  const bool sheet = IsSheet(args);
  return args.positionals().empty() == sheet && (!sheet || (args.Has("ids") && args.Has("size") && args.Has("out")));
}

// reconar tags IMAGES...: the tags in each photo.
int RunDetect(const Args& args, TagFamily family) {
  auto paths = CollectImagePaths(args.positionals());
  if (!paths.ok()) return Fail(paths.status());
  PhotoTagOptions options;
  options.family = family;
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.num_threads = *threads;
  options.show_progress = false;
  auto photos = DetectAllTagsInPhotos(*paths, options);
  if (!photos.ok()) return Fail(photos.status());
  for (const PhotoDetections& photo : *photos) {
    if (args.Has("json")) {
      std::printf("%s\n", PhotoJson(photo, TagFamilyName(family)).c_str());
      continue;
    }
    std::printf("%s %dx%d: %zu tag(s)", photo.image_name.c_str(), photo.width, photo.height, photo.detections.size());
    for (const TagDetection& tag : photo.detections) std::printf(" %d", tag.id);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int RunTags(int argc, char** argv, int first) {
  Args args({"family", "ids", "size", "paper", "margin", "out", "threads"}, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, {0, SIZE_MAX, {}, IsRightUsage})) {
    return *exit_code;
  }
  const bool sheet = IsSheet(args);
  const std::string family_name = args.Get("family", "tag36h11");
  auto family = ParseTagFamily(family_name);
  if (!family.ok()) return Fail(family.status());
  if (!sheet) return RunDetect(args, *family);

  const std::string out = args.Get("out");
  const std::string extension = LowercaseExtension(out);
  if (extension != ".svg" && extension != ".pdf") {
    return Fail(InvalidArgument("--out: '" + out + "' must end in .svg or .pdf"));
  }
  TagSheetOptions options;
  options.family = family_name;
  auto size = args.GetDouble("size", 0.0, 1e-4, 10.0);
  if (!size.ok()) return Fail(size.status());
  options.tag_size_mm = *size * 1000.0;
  if (Status s = SetPaperSize(args.Get("paper", "a4"), &options); !s.ok()) return Fail(s.WithContext("--paper"));
  auto margin = args.GetDouble("margin", options.margin_mm, 0.0, 100.0);
  if (!margin.ok()) return Fail(margin.status());
  options.margin_mm = *margin;
  auto ids = ParseIds(args.Get("ids"));
  if (!ids.ok()) return Fail(ids.status());

  auto bitmaps = RenderSheetTags(*family, *ids);
  if (!bitmaps.ok()) return Fail(bitmaps.status().WithContext("--ids"));
  auto sheet_layout = LayoutTagSheet(std::move(*bitmaps), options);
  if (!sheet_layout.ok()) return Fail(sheet_layout.status());
  auto written = WriteTagSheet(*sheet_layout, out);
  if (!written.ok()) return Fail(written.status());
  std::fprintf(stderr, "reconar tags: %zu %s tag(s) of %.1f mm on %zu page(s):", ids->size(), options.family.c_str(),
               options.tag_size_mm, sheet_layout->pages.size());
  for (const std::string& path : *written) std::fprintf(stderr, " %s", path.c_str());
  std::fputc('\n', stderr);
  if (args.Has("json")) {
    JsonWriter json;
    json.BeginObject().Key("family").String(options.family).Key("ids").BeginArray();
    for (const int id : *ids) json.Int(id);
    json.EndArray().Key("size_mm").Double(options.tag_size_mm).Key("files").BeginArray();
    for (const std::string& path : *written) json.String(path);
    json.EndArray().EndObject();
    std::printf("%s\n", json.str().c_str());
  }
  return 0;
}

}  // namespace reconar::tools
