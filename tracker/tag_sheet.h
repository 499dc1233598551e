#pragma once
// Printable AprilTag sheets (`reconar tags`): tags laid out on paper pages, written as SVG (one
// file per page) or PDF (one file, a page each). Sizes are exact: a tag's size is the edge of its
// detection border (libapriltag's tag_size, e.g. the black square of tag36h11), so the module
// edge is size / width_at_border and the whole bitmap, quiet zone included, is total_width modules.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "tracker/tag_detector.h"

namespace reconar {

struct SheetTag {
  int id = 0;
  int total_width = 0;      // modules per side, white quiet zone included
  int width_at_border = 0;  // modules across the detection border: what the tag size measures
  std::vector<bool> black;  // total_width² modules, row-major, row 0 at the top
};

struct TagSheetOptions {
  double tag_size_mm = 160.0;
  double page_width_mm = 210.0;  // A4 portrait
  double page_height_mm = 297.0;
  double margin_mm = 10.0;
  double gap_mm = 8.0;  // between neighbouring bitmaps (their quiet zones add to it)
  std::string family = "tag36h11";
};

struct PlacedTag {
  int id = 0;
  double x_mm = 0.0;  // top-left corner of the detection border, page coordinates (y down)
  double y_mm = 0.0;
};

struct TagSheetPage {
  std::vector<PlacedTag> tags;
};

struct TagSheet {
  TagSheetOptions options;
  std::vector<SheetTag> bitmaps;  // in the order of the ids asked for
  std::vector<TagSheetPage> pages;
};

// Lays the tags out row by row, as many per page as fit. InvalidArgument when one tag does not fit.
Result<TagSheet> LayoutTagSheet(std::vector<SheetTag> bitmaps, const TagSheetOptions& options);

std::string RenderSvgPage(const TagSheet& sheet, size_t page);
std::string RenderPdf(const TagSheet& sheet);

// The printable bitmaps of `ids` in `family` (RenderTagBitmap); InvalidArgument naming an id that
// is not a code of the family.
Result<std::vector<SheetTag>> RenderSheetTags(TagFamily family, const std::vector<int>& ids);

// Page size by name: a4 (210 x 297 mm), a3, letter, or WIDTHxHEIGHT in mm (e.g. 300x400).
Status SetPaperSize(const std::string& name, TagSheetOptions* options);

// Writes the sheet atomically: .pdf one file with a page each; .svg one file per page (PATH,
// then PATH-2.svg, PATH-3.svg, ...). Returns the files written; InvalidArgument for another extension.
Result<std::vector<std::string>> WriteTagSheet(const TagSheet& sheet, const std::string& path);

}  // namespace reconar
