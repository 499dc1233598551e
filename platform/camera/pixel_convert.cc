#include "platform/camera/pixel_convert.h"

#include "core/base/check.h"

namespace reconar {

namespace {

constexpr int kShift = 16;
constexpr int32_t kHalf = 1 << (kShift - 1);

// BT.601 in 16.16 fixed point. Limited range (ITU-R BT.601): R = 1.164383 (Y-16) + 1.596027 (Cr-128), ...
// Full range (JFIF, libjpeg jdcolor.c FIX() values): R = Y + 1.402 (Cr-128), ...
struct YuvCoefficients {
  int32_t y_offset;
  int32_t y_scale;
  int32_t cr_to_r;
  int32_t cb_to_g;  // subtracted
  int32_t cr_to_g;  // subtracted
  int32_t cb_to_b;
};

constexpr YuvCoefficients kLimited{16, 76309, 104597, 25675, 53279, 132201};
constexpr YuvCoefficients kFull{0, 65536, 91881, 22554, 46802, 116130};

const YuvCoefficients& Coefficients(YuvRange range) { return range == YuvRange::kFull ? kFull : kLimited; }

uint8_t Clamp255(int32_t value) {
  return static_cast<uint8_t>(value < 0 ? 0 : (value > 255 ? 255 : value));
}

// Arithmetic right shift with libjpeg's rounding (add half, shift, which floors negatives).
int32_t Descale(int32_t value) { return (value + kHalf) >> kShift; }

uint8_t ScaleLuma(const YuvCoefficients& c, uint8_t y) { return Clamp255(Descale((y - c.y_offset) * c.y_scale)); }

// Luma expansion as a 256-entry table (on the stack: filled per call, 256 multiplies).
struct LumaTable {
  explicit LumaTable(const YuvCoefficients& c) {
    for (int y = 0; y < 256; ++y) values[y] = ScaleLuma(c, static_cast<uint8_t>(y));
  }
  uint8_t values[256];
};

// The chroma contribution of one (Cb, Cr) pair, shared by the pixels it covers.
struct ChromaTerms {
  int32_t r;
  int32_t g;
  int32_t b;
};

ChromaTerms Chroma(const YuvCoefficients& c, uint8_t cb, uint8_t cr) {
  const int32_t u = cb - 128;
  const int32_t v = cr - 128;
  return {c.cr_to_r * v, -c.cb_to_g * u - c.cr_to_g * v, c.cb_to_b * u};
}

void StoreRgb(const YuvCoefficients& c, uint8_t y, const ChromaTerms& chroma, uint8_t* out) {
  const int32_t luma = (y - c.y_offset) * c.y_scale;
  out[0] = Clamp255(Descale(luma + chroma.r));
  out[1] = Clamp255(Descale(luma + chroma.g));
  out[2] = Clamp255(Descale(luma + chroma.b));
}

void CheckSameSize(int width, int height, const ImageView<uint8_t>& out, int channels) {
  RECONAR_CHECK(out.width == width * channels && out.height == height)
      << "output view " << out.width << "x" << out.height << " does not fit " << width << "x" << height << "x"
      << channels;
}

int YuyvPixels(const ImageView<const uint8_t>& yuyv) {
  RECONAR_CHECK(yuyv.width % 4 == 0) << "YUYV rows hold whole pixel pairs (got " << yuyv.width << " bytes)";
  return yuyv.width / 2;
}

}  // namespace

void ExtractYuyvLuma(const ImageView<const uint8_t>& yuyv, const ImageView<uint8_t>& gray) {
  const int width = YuyvPixels(yuyv);
  CheckSameSize(width, yuyv.height, gray, 1);
  for (int y = 0; y < yuyv.height; ++y) {
    const uint8_t* in = yuyv.row(y);
    uint8_t* out = gray.row(y);
    for (int x = 0; x < width; ++x) out[x] = in[2 * x];
  }
}

void YuyvToGray(const ImageView<const uint8_t>& yuyv, const YuvConversionOptions& options,
                const ImageView<uint8_t>& gray) {
  if (options.range == YuvRange::kFull) {
    ExtractYuyvLuma(yuyv, gray);
    return;
  }
  const int width = YuyvPixels(yuyv);
  CheckSameSize(width, yuyv.height, gray, 1);
  const LumaTable table(Coefficients(options.range));
  for (int y = 0; y < yuyv.height; ++y) {
    const uint8_t* in = yuyv.row(y);
    uint8_t* out = gray.row(y);
    for (int x = 0; x < width; ++x) out[x] = table.values[in[2 * x]];
  }
}

void LumaToGray(const ImageView<const uint8_t>& luma, const YuvConversionOptions& options,
                const ImageView<uint8_t>& gray) {
  if (options.range == YuvRange::kFull) {
    CopyPlane(luma, gray);
    return;
  }
  CheckSameSize(luma.width, luma.height, gray, 1);
  const LumaTable table(Coefficients(options.range));
  for (int y = 0; y < luma.height; ++y) {
    const uint8_t* in = luma.row(y);
    uint8_t* out = gray.row(y);
    for (int x = 0; x < luma.width; ++x) out[x] = table.values[in[x]];
  }
}

void YuyvToRgb(const ImageView<const uint8_t>& yuyv, const YuvConversionOptions& options,
               const ImageView<uint8_t>& rgb) {
  const int width = YuyvPixels(yuyv);
  CheckSameSize(width, yuyv.height, rgb, 3);
  const YuvCoefficients& c = Coefficients(options.range);
  for (int y = 0; y < yuyv.height; ++y) {
    const uint8_t* in = yuyv.row(y);
    uint8_t* out = rgb.row(y);
    for (int x = 0; x < width; x += 2, in += 4, out += 6) {
      const ChromaTerms chroma = Chroma(c, in[1], in[3]);
      StoreRgb(c, in[0], chroma, out);
      StoreRgb(c, in[2], chroma, out + 3);
    }
  }
}

void Nv12ToRgb(const ImageView<const uint8_t>& luma, const ImageView<const uint8_t>& chroma,
               const YuvConversionOptions& options, const ImageView<uint8_t>& rgb) {
  const int width = luma.width;
  const int height = luma.height;
  CheckSameSize(width, height, rgb, 3);
  RECONAR_CHECK(chroma.width == 2 * ((width + 1) / 2) && chroma.height == (height + 1) / 2)
      << "NV12 chroma plane " << chroma.width << "x" << chroma.height << " does not fit " << width << "x" << height;
  const YuvCoefficients& c = Coefficients(options.range);
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = luma.row(y);
    const uint8_t* uv = chroma.row(y / 2);
    uint8_t* out = rgb.row(y);
    for (int x = 0; x + 1 < width; x += 2) {
      const ChromaTerms terms = Chroma(c, uv[x], uv[x + 1]);
      StoreRgb(c, in[x], terms, out + 3 * x);
      StoreRgb(c, in[x + 1], terms, out + 3 * x + 3);
    }
    if (width % 2 != 0) StoreRgb(c, in[width - 1], Chroma(c, uv[width - 1], uv[width]), out + 3 * (width - 1));
  }
}

void YcbcrToRgb(const ImageView<const uint8_t>& ycbcr, const YuvConversionOptions& options,
                const ImageView<uint8_t>& rgb) {
  RECONAR_CHECK(ycbcr.width % 3 == 0) << "Y,Cb,Cr rows hold whole triples";
  CheckSameSize(ycbcr.width / 3, ycbcr.height, rgb, 3);
  const YuvCoefficients& c = Coefficients(options.range);
  for (int y = 0; y < ycbcr.height; ++y) {
    const uint8_t* in = ycbcr.row(y);
    uint8_t* out = rgb.row(y);
    for (int x = 0; x < ycbcr.width; x += 3) StoreRgb(c, in[x], Chroma(c, in[x + 1], in[x + 2]), out + x);
  }
}

void ExtractYcbcrLuma(const ImageView<const uint8_t>& ycbcr, const ImageView<uint8_t>& gray) {
  RECONAR_CHECK(ycbcr.width % 3 == 0) << "Y,Cb,Cr rows hold whole triples";
  CheckSameSize(ycbcr.width / 3, ycbcr.height, gray, 1);
  for (int y = 0; y < ycbcr.height; ++y) {
    const uint8_t* in = ycbcr.row(y);
    uint8_t* out = gray.row(y);
    for (int x = 0; x < gray.width; ++x) out[x] = in[3 * x];
  }
}

void CopyPlane(const ImageView<const uint8_t>& from, const ImageView<uint8_t>& to) {
  CheckSameSize(from.width, from.height, to, 1);
  for (int y = 0; y < from.height; ++y) {
    const uint8_t* in = from.row(y);
    uint8_t* out = to.row(y);
    for (int x = 0; x < from.width; ++x) out[x] = in[x];
  }
}

void GrayToRgb(const ImageView<const uint8_t>& gray, const ImageView<uint8_t>& rgb) {
  CheckSameSize(gray.width, gray.height, rgb, 3);
  for (int y = 0; y < gray.height; ++y) {
    const uint8_t* in = gray.row(y);
    uint8_t* out = rgb.row(y);
    for (int x = 0; x < gray.width; ++x) out[3 * x] = out[3 * x + 1] = out[3 * x + 2] = in[x];
  }
}

void RgbToGray(const ImageView<const uint8_t>& rgb, const ImageView<uint8_t>& gray) {
  RECONAR_CHECK(rgb.width % 3 == 0) << "RGB rows hold whole triples";
  CheckSameSize(rgb.width / 3, rgb.height, gray, 1);
  for (int y = 0; y < rgb.height; ++y) {
    const uint8_t* in = rgb.row(y);
    uint8_t* out = gray.row(y);
    for (int x = 0; x < gray.width; ++x, in += 3) {
      out[x] = static_cast<uint8_t>(Descale(19595 * in[0] + 38470 * in[1] + 7471 * in[2]));
    }
  }
}

}  // namespace reconar
