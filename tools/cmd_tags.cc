// reconar tags: a printable sheet of AprilTags whose detection border measures exactly --size.
#include <cstdio>
#include <string>
#include <vector>

#include "tools/commands.h"
#include "tracker/tag_detector.h"
#include "tracker/tag_sheet.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar tags --ids LIST --size METRES --out FILE.{svg,pdf} [options]\n"
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
    "  --out FILE        .svg or .pdf\n";

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

}  // namespace

int RunTags(int argc, char** argv, int first) {
  Args args({"family", "ids", "size", "paper", "margin", "out"}, {});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (!args.positionals().empty() || !args.Has("ids") || !args.Has("size") || !args.Has("out")) {
    std::fputs(kHelp, stderr);
    return 2;
  }
  const std::string out = args.Get("out");
  const std::string extension = LowercaseExtension(out);
  if (extension != ".svg" && extension != ".pdf") {
    return Fail(InvalidArgument("--out: '" + out + "' must end in .svg or .pdf"));
  }
  TagSheetOptions options;
  options.family = args.Get("family", "tag36h11");
  auto family = ParseTagFamily(options.family);
  if (!family.ok()) return Fail(family.status());
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
  auto sheet = LayoutTagSheet(std::move(*bitmaps), options);
  if (!sheet.ok()) return Fail(sheet.status());
  auto written = WriteTagSheet(*sheet, out);
  if (!written.ok()) return Fail(written.status());
  std::fprintf(stderr, "reconar tags: %zu %s tag(s) of %.1f mm on %zu page(s):", ids->size(), options.family.c_str(),
               options.tag_size_mm, sheet->pages.size());
  for (const std::string& path : *written) std::fprintf(stderr, " %s", path.c_str());
  std::fputc('\n', stderr);
  return 0;
}

}  // namespace reconar::tools
