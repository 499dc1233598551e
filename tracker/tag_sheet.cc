#include "tracker/tag_sheet.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

constexpr double kLabelHeightMm = 6.0;
constexpr double kPointsPerMm = 72.0 / 25.4;
constexpr double kScaleBarMm = 100.0;

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4f", value);
  std::string out(text);
  while (!out.empty() && out.back() == '0') out.pop_back();
  if (!out.empty() && out.back() == '.') out.pop_back();
  return out == "-0" ? "0" : out;
}

double ModuleMm(const TagSheet& sheet, const SheetTag& bitmap) {
  return sheet.options.tag_size_mm / bitmap.width_at_border;
}

// One rectangle per horizontal run of black modules: x, y (top-left, mm, y down), width, height.
struct RectMm {
  double x, y, width, height;
};

template <typename Emit>
void ForEachBlackRun(const TagSheet& sheet, const SheetTag& bitmap, const PlacedTag& placed, Emit emit) {
  const double module = ModuleMm(sheet, bitmap);
  const int quiet = (bitmap.total_width - bitmap.width_at_border) / 2;
  const double origin_x = placed.x_mm - quiet * module;
  const double origin_y = placed.y_mm - quiet * module;
  const int n = bitmap.total_width;
  for (int row = 0; row < n; ++row) {
    int col = 0;
    while (col < n) {
      if (!bitmap.black[static_cast<size_t>(row) * n + col]) {
        ++col;
        continue;
      }
      const int start = col;
      while (col < n && bitmap.black[static_cast<size_t>(row) * n + col]) ++col;
      emit(RectMm{origin_x + start * module, origin_y + row * module, (col - start) * module, module});
    }
  }
}

std::string Caption(const TagSheet& sheet, const SheetTag& bitmap) {
  return sheet.options.family + " id " + std::to_string(bitmap.id) + ", edge " + Number(sheet.options.tag_size_mm) +
         " mm";
}

std::string ScaleBarCaption() {
  return "this bar must measure " + Number(kScaleBarMm) + " mm: print at 100 %, no fit-to-page";
}

}  // namespace

Result<TagSheet> LayoutTagSheet(std::vector<SheetTag> bitmaps, const TagSheetOptions& options) {
  if (bitmaps.empty()) return InvalidArgument("no tags to lay out");
  if (!(options.tag_size_mm > 0.0)) return InvalidArgument("tag size must be positive");
  TagSheet sheet;
  sheet.options = options;
  sheet.bitmaps = std::move(bitmaps);
  const SheetTag& first = sheet.bitmaps.front();
  const double module = options.tag_size_mm / first.width_at_border;
  const double quiet = (first.total_width - first.width_at_border) / 2 * module;
  const double cell_width = options.tag_size_mm + 2 * quiet + options.gap_mm;
  const double cell_height = cell_width + kLabelHeightMm;
  const double usable_width = options.page_width_mm - 2 * options.margin_mm;
  // The bottom margin also holds the scale bar.
  const double usable_height = options.page_height_mm - 2 * options.margin_mm - 2 * kLabelHeightMm;
  const int columns = static_cast<int>(std::floor((usable_width + options.gap_mm) / cell_width));
  const int rows = static_cast<int>(std::floor((usable_height + options.gap_mm) / cell_height));
  if (columns < 1 || rows < 1) {
    return InvalidArgument("a " + Number(options.tag_size_mm) + " mm tag with its quiet zone does not fit on a " +
                           Number(options.page_width_mm) + " x " + Number(options.page_height_mm) + " mm page with " +
                           Number(options.margin_mm) + " mm margins");
  }
  const size_t per_page = static_cast<size_t>(columns) * rows;
  for (size_t i = 0; i < sheet.bitmaps.size(); ++i) {
    if (i % per_page == 0) sheet.pages.emplace_back();
    const size_t slot = i % per_page;
    const int column = static_cast<int>(slot % columns);
    const int row = static_cast<int>(slot / columns);
    PlacedTag placed;
    placed.id = sheet.bitmaps[i].id;
    placed.x_mm = options.margin_mm + column * cell_width + quiet;
    placed.y_mm = options.margin_mm + row * cell_height + quiet;
    sheet.pages.back().tags.push_back(placed);
  }
  return sheet;
}

namespace {
const SheetTag& BitmapFor(const TagSheet& sheet, int id) {
  for (const SheetTag& bitmap : sheet.bitmaps) {
    if (bitmap.id == id) return bitmap;
  }
  return sheet.bitmaps.front();
}
}  // namespace

std::string RenderSvgPage(const TagSheet& sheet, size_t page) {
  const TagSheetOptions& o = sheet.options;
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Number(o.page_width_mm) << "mm\" height=\""
      << Number(o.page_height_mm) << "mm\" viewBox=\"0 0 " << Number(o.page_width_mm) << ' ' << Number(o.page_height_mm)
      << "\" shape-rendering=\"crispEdges\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << Number(o.page_width_mm) << "\" height=\"" << Number(o.page_height_mm)
      << "\" fill=\"#fff\"/>\n";
  for (const PlacedTag& placed : sheet.pages[page].tags) {
    const SheetTag& bitmap = BitmapFor(sheet, placed.id);
    svg << "<g fill=\"#000\">\n";
    ForEachBlackRun(sheet, bitmap, placed, [&](const RectMm& r) {
      svg << "<rect x=\"" << Number(r.x) << "\" y=\"" << Number(r.y) << "\" width=\"" << Number(r.width)
          << "\" height=\"" << Number(r.height) << "\"/>\n";
    });
    const double quiet = (bitmap.total_width - bitmap.width_at_border) / 2 * ModuleMm(sheet, bitmap);
    svg << "</g>\n<text x=\"" << Number(placed.x_mm) << "\" y=\""
        << Number(placed.y_mm + o.tag_size_mm + quiet + 0.7 * kLabelHeightMm)
        << "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"3.5\">" << Caption(sheet, bitmap)
        << "</text>\n";
  }
  const double bar_y = o.page_height_mm - o.margin_mm - kLabelHeightMm;
  svg << "<rect x=\"" << Number(o.margin_mm) << "\" y=\"" << Number(bar_y) << "\" width=\"" << Number(kScaleBarMm)
      << "\" height=\"1\" fill=\"#000\"/>\n"
      << "<text x=\"" << Number(o.margin_mm) << "\" y=\"" << Number(bar_y + 5)
      << "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"3\">" << ScaleBarCaption() << "</text>\n"
      << "</svg>\n";
  return svg.str();
}

std::string RenderPdf(const TagSheet& sheet) {
  const TagSheetOptions& o = sheet.options;
  const double page_width_pt = o.page_width_mm * kPointsPerMm;
  const double page_height_pt = o.page_height_mm * kPointsPerMm;
  // PDF user space has y up in points; page coordinates here are mm with y down.
  auto x_pt = [&](double x_mm) { return Number(x_mm * kPointsPerMm); };
  auto y_pt = [&](double y_mm) { return Number(page_height_pt - y_mm * kPointsPerMm); };

  std::vector<std::string> objects;  // object k+1 is objects[k]
  objects.push_back("<< /Type /Catalog /Pages 2 0 R >>");
  objects.push_back("");  // pages, filled in below
  objects.push_back("<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>");
  std::string kids;
  for (size_t page = 0; page < sheet.pages.size(); ++page) {
    std::ostringstream content;
    content << "0 g\n";
    for (const PlacedTag& placed : sheet.pages[page].tags) {
      const SheetTag& bitmap = BitmapFor(sheet, placed.id);
      ForEachBlackRun(sheet, bitmap, placed, [&](const RectMm& r) {
        content << x_pt(r.x) << ' ' << y_pt(r.y + r.height) << ' ' << Number(r.width * kPointsPerMm) << ' '
                << Number(r.height * kPointsPerMm) << " re\n";
      });
      content << "f\n";
      const double quiet = (bitmap.total_width - bitmap.width_at_border) / 2 * ModuleMm(sheet, bitmap);
      content << "BT /F1 10 Tf " << x_pt(placed.x_mm) << ' '
              << y_pt(placed.y_mm + o.tag_size_mm + quiet + 0.7 * kLabelHeightMm) << " Td (" << Caption(sheet, bitmap)
              << ") Tj ET\n";
    }
    const double bar_y = o.page_height_mm - o.margin_mm - kLabelHeightMm;
    content << x_pt(o.margin_mm) << ' ' << y_pt(bar_y + 1) << ' ' << Number(kScaleBarMm * kPointsPerMm) << ' '
            << Number(kPointsPerMm) << " re f\n"
            << "BT /F1 8 Tf " << x_pt(o.margin_mm) << ' ' << y_pt(bar_y + 5) << " Td (" << ScaleBarCaption()
            << ") Tj ET\n";
    const std::string stream = content.str();
    const size_t content_object = objects.size() + 2;
    objects.push_back("<< /Type /Page /Parent 2 0 R /MediaBox [0 0 " + Number(page_width_pt) + ' ' +
                      Number(page_height_pt) + "] /Resources << /Font << /F1 3 0 R >> >> /Contents " +
                      std::to_string(content_object) + " 0 R >>");
    objects.push_back("<< /Length " + std::to_string(stream.size()) + " >>\nstream\n" + stream + "endstream");
    kids += std::to_string(objects.size() - 1) + " 0 R ";
  }
  objects[1] = "<< /Type /Pages /Kids [" + kids + "] /Count " + std::to_string(sheet.pages.size()) + " >>";

  std::string pdf = "%PDF-1.4\n%\xE2\xE3\xCF\xD3\n";
  std::vector<size_t> offsets;
  for (size_t k = 0; k < objects.size(); ++k) {
    offsets.push_back(pdf.size());
    pdf += std::to_string(k + 1) + " 0 obj\n" + objects[k] + "\nendobj\n";
  }
  const size_t xref_offset = pdf.size();
  pdf += "xref\n0 " + std::to_string(objects.size() + 1) + "\n0000000000 65535 f \n";
  for (size_t offset : offsets) {
    char entry[24];
    std::snprintf(entry, sizeof(entry), "%010zu 00000 n \n", offset);
    pdf += entry;
  }
  pdf += "trailer\n<< /Size " + std::to_string(objects.size() + 1) + " /Root 1 0 R >>\nstartxref\n" +
         std::to_string(xref_offset) + "\n%%EOF\n";
  return pdf;
}

Result<std::vector<SheetTag>> RenderSheetTags(TagFamily family, const std::vector<int>& ids) {
  std::vector<SheetTag> bitmaps;
  for (int id : ids) {
    RECONAR_ASSIGN_OR_RETURN(const TagBitmap rendered, RenderTagBitmap(family, id));
    SheetTag bitmap;
    bitmap.id = id;
    bitmap.total_width = rendered.pixels.width();
    bitmap.width_at_border = rendered.width_at_border;
    for (int y = 0; y < rendered.pixels.height(); ++y) {
      for (int x = 0; x < rendered.pixels.width(); ++x) bitmap.black.push_back(rendered.pixels.row(y)[x] < 128);
    }
    bitmaps.push_back(std::move(bitmap));
  }
  return bitmaps;
}

Status SetPaperSize(const std::string& name, TagSheetOptions* options) {
  if (name == "a4") {
    options->page_width_mm = 210, options->page_height_mm = 297;
  } else if (name == "a3") {
    options->page_width_mm = 297, options->page_height_mm = 420;
  } else if (name == "letter") {
    options->page_width_mm = 215.9, options->page_height_mm = 279.4;
  } else {
    double width = 0, height = 0;
    char extra = 0;
    if (std::sscanf(name.c_str(), "%lfx%lf%c", &width, &height, &extra) != 2 || width <= 0 || height <= 0) {
      return InvalidArgument("paper '" + name + "' is not a4, a3, letter or WIDTHxHEIGHT in mm");
    }
    options->page_width_mm = width, options->page_height_mm = height;
  }
  return Status::Ok();
}

Result<std::vector<std::string>> WriteTagSheet(const TagSheet& sheet, const std::string& path) {
  std::string extension = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::vector<std::string> written;
  if (extension == ".pdf") {
    RECONAR_RETURN_IF_ERROR(WriteFileAtomically(path, RenderPdf(sheet)));
    written.push_back(path);
  } else if (extension == ".svg") {
    for (size_t page = 0; page < sheet.pages.size(); ++page) {
      const std::string page_path =
          page == 0 ? path : path.substr(0, path.size() - 4) + "-" + std::to_string(page + 1) + ".svg";
      RECONAR_RETURN_IF_ERROR(WriteFileAtomically(page_path, RenderSvgPage(sheet, page)));
      written.push_back(page_path);
    }
  } else {
    return InvalidArgument(path + ": a tag sheet is written as .svg or .pdf");
  }
  return written;
}

}  // namespace reconar
