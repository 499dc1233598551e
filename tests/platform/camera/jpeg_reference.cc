#include "tests/platform/camera/jpeg_reference.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <jpeglib.h>

#include "core/base/check.h"
#include "core/io/image_write.h"

namespace reconar::testing {

std::string ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

namespace {

void StartDecompress(jpeg_decompress_struct* cinfo, jpeg_error_mgr* err, const std::string& jpeg) {
  cinfo->err = jpeg_std_error(err);  // test data is known good: libjpeg's exit-on-error is fine
  jpeg_create_decompress(cinfo);
  jpeg_mem_src(cinfo, reinterpret_cast<const unsigned char*>(jpeg.data()), static_cast<unsigned long>(jpeg.size()));
  jpeg_read_header(cinfo, TRUE);
}

}  // namespace

bool ReadYcbcr420Planes(const std::string& jpeg, YcbcrPlanes* planes, std::string* reason) {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr err{};
  StartDecompress(&cinfo, &err, jpeg);
  const jpeg_component_info* c = cinfo.comp_info;
  if (cinfo.num_components != 3 || cinfo.jpeg_color_space != JCS_YCbCr || c[0].h_samp_factor != 2 ||
      c[0].v_samp_factor != 2 || c[1].h_samp_factor != 1 || c[1].v_samp_factor != 1 || c[2].h_samp_factor != 1 ||
      c[2].v_samp_factor != 1) {
    *reason = "not 4:2:0 YCbCr: components " + std::to_string(cinfo.num_components) + ", Y sampling " +
              std::to_string(c[0].h_samp_factor) + "x" + std::to_string(c[0].v_samp_factor);
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  cinfo.raw_data_out = TRUE;
  jpeg_start_decompress(&cinfo);
  planes->width = static_cast<int>(cinfo.image_width);
  planes->height = static_cast<int>(cinfo.image_height);
  planes->chroma_width = (planes->width + 1) / 2;
  planes->chroma_height = (planes->height + 1) / 2;
  // Raw output covers whole MCUs (16x16 luma): pad the planes to them.
  const int mcu_rows = static_cast<int>((cinfo.image_height + 15) / 16);
  planes->y_pitch = static_cast<int>(c[0].width_in_blocks) * DCTSIZE;
  planes->chroma_pitch = static_cast<int>(c[1].width_in_blocks) * DCTSIZE;
  planes->y.assign(static_cast<size_t>(planes->y_pitch) * 16 * mcu_rows, 0);
  planes->cb.assign(static_cast<size_t>(planes->chroma_pitch) * 8 * mcu_rows, 0);
  planes->cr.assign(planes->cb.size(), 0);
  JSAMPROW y_rows[16], cb_rows[8], cr_rows[8];
  JSAMPARRAY arrays[3] = {y_rows, cb_rows, cr_rows};
  for (int mcu = 0; mcu < mcu_rows; ++mcu) {
    for (int r = 0; r < 16; ++r) y_rows[r] = planes->y.data() + static_cast<size_t>(mcu * 16 + r) * planes->y_pitch;
    for (int r = 0; r < 8; ++r) {
      cb_rows[r] = planes->cb.data() + static_cast<size_t>(mcu * 8 + r) * planes->chroma_pitch;
      cr_rows[r] = planes->cr.data() + static_cast<size_t>(mcu * 8 + r) * planes->chroma_pitch;
    }
    jpeg_read_raw_data(&cinfo, arrays, 16);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

std::vector<uint8_t> LibjpegDecode(const std::string& jpeg, int out_components, bool fancy_upsampling, int* width,
                                   int* height) {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr err{};
  StartDecompress(&cinfo, &err, jpeg);
  cinfo.out_color_space = out_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  cinfo.do_fancy_upsampling = fancy_upsampling ? TRUE : FALSE;
  jpeg_start_decompress(&cinfo);
  const size_t row_bytes = static_cast<size_t>(cinfo.output_width) * out_components;
  std::vector<uint8_t> pixels(row_bytes * cinfo.output_height);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = pixels.data() + cinfo.output_scanline * row_bytes;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  if (width != nullptr) *width = static_cast<int>(cinfo.output_width);
  if (height != nullptr) *height = static_cast<int>(cinfo.output_height);
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return pixels;
}

std::string LibjpegEncodeRgb(const std::vector<uint8_t>& rgb, int width, int height, int quality) {
  auto bytes = EncodeJpeg(ImageView<const uint8_t>(3 * width, height, 3 * width, rgb.data()), 3, quality);
  RECONAR_CHECK(bytes.ok()) << bytes.status().ToString();
  return *bytes;
}

std::vector<uint8_t> PackNv12(const YcbcrPlanes& p, int pitch) {
  std::vector<uint8_t> out(static_cast<size_t>(pitch) * (p.height + p.chroma_height), 0xAB);
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) out[static_cast<size_t>(y) * pitch + x] = p.y[static_cast<size_t>(y) * p.y_pitch + x];
  }
  uint8_t* uv = out.data() + static_cast<size_t>(pitch) * p.height;
  for (int y = 0; y < p.chroma_height; ++y) {
    for (int x = 0; x < p.chroma_width; ++x) {
      uv[static_cast<size_t>(y) * pitch + 2 * x] = p.cb[static_cast<size_t>(y) * p.chroma_pitch + x];
      uv[static_cast<size_t>(y) * pitch + 2 * x + 1] = p.cr[static_cast<size_t>(y) * p.chroma_pitch + x];
    }
  }
  return out;
}

std::vector<uint8_t> PackYuyv(const YcbcrPlanes& p, int pitch) {
  std::vector<uint8_t> out(static_cast<size_t>(pitch) * p.height, 0xAB);
  for (int y = 0; y < p.height; ++y) {
    uint8_t* row = out.data() + static_cast<size_t>(y) * pitch;
    const size_t chroma_row = static_cast<size_t>(y / 2) * p.chroma_pitch;
    for (int x = 0; x < p.width; x += 2) {
      row[2 * x] = p.y[static_cast<size_t>(y) * p.y_pitch + x];
      row[2 * x + 1] = p.cb[chroma_row + x / 2];
      row[2 * x + 2] = p.y[static_cast<size_t>(y) * p.y_pitch + x + 1];
      row[2 * x + 3] = p.cr[chroma_row + x / 2];
    }
  }
  return out;
}

}  // namespace reconar::testing
