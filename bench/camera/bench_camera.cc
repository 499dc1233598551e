// Milliseconds per frame of the camera conversion paths on a real 640x480 JPEG frame:
// YUYV → RGB + gray, NV12 → RGB (gray zero-copy), MJPEG → gray + RGB, MJPEG → gray only.
// Usage: bench_camera [JPEG] [repetitions]   (default: apriltag_ar_video_id12 frame0000.jpg, 200)
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "platform/camera/raw_frame.h"

namespace {

using reconar::ImageView;

uint8_t Clamp(double v) { return static_cast<uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v + 0.5)); }

template <typename Body>
double MillisecondsPerCall(int repetitions, Body body) {
  body();  // warm-up (sizes buffers, faults pages in)
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repetitions; ++i) body();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / repetitions;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace reconar;
  const std::string path = argc > 1 ? argv[1]
                                    : std::string(RECONAR_SHARED_DATA_DIR) +
                                          "/apriltag_ar_video_id12/frames/frame0000.jpg";
  const int repetitions = argc > 2 ? std::atoi(argv[2]) : 200;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  const std::string jpeg = content.str();
  if (jpeg.empty()) {
    std::fprintf(stderr, "bench_camera: cannot read %s\n", path.c_str());
    return 2;
  }

  JpegFrameDecoder decoder;
  auto header = decoder.ReadHeader(reinterpret_cast<const uint8_t*>(jpeg.data()), jpeg.size(), path);
  if (!header.ok()) {
    std::fprintf(stderr, "bench_camera: %s\n", header.status().ToString().c_str());
    return 2;
  }
  const int w = header->width & ~1;
  const int h = header->height & ~1;
  std::vector<uint8_t> gray(static_cast<size_t>(header->width) * header->height);
  std::vector<uint8_t> rgb(3 * gray.size());
  const ImageView<uint8_t> gray_full(header->width, header->height, header->width, gray.data());
  const ImageView<uint8_t> rgb_full(3 * header->width, header->height, 3 * header->width, rgb.data());
  if (!decoder.Decode(reinterpret_cast<const uint8_t*>(jpeg.data()), jpeg.size(), path, gray_full, rgb_full).ok()) {
    std::fprintf(stderr, "bench_camera: %s does not decode\n", path.c_str());
    return 2;
  }

  // Camera layouts of the decoded picture (full-range BT.601, chroma averaged over 2x2 / 2x1).
  std::vector<uint8_t> nv12(static_cast<size_t>(w) * h * 3 / 2);
  std::vector<uint8_t> yuyv(static_cast<size_t>(w) * h * 2);
  auto chroma = [&](int x, int y, double* cb, double* cr) {
    const uint8_t* p = &rgb[(static_cast<size_t>(y) * header->width + x) * 3];
    *cb = 128 - 0.168736 * p[0] - 0.331264 * p[1] + 0.5 * p[2];
    *cr = 128 + 0.5 * p[0] - 0.418688 * p[1] - 0.081312 * p[2];
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      nv12[static_cast<size_t>(y) * w + x] = gray[static_cast<size_t>(y) * header->width + x];
      yuyv[(static_cast<size_t>(y) * w + x) * 2] = gray[static_cast<size_t>(y) * header->width + x];
    }
    for (int x = 0; x < w; x += 2) {
      double cb0, cr0, cb1, cr1;
      chroma(x, y, &cb0, &cr0);
      chroma(x + 1, y, &cb1, &cr1);
      yuyv[(static_cast<size_t>(y) * w + x) * 2 + 1] = Clamp((cb0 + cb1) / 2);
      yuyv[(static_cast<size_t>(y) * w + x) * 2 + 3] = Clamp((cr0 + cr1) / 2);
      if (y % 2 == 0) {
        double cb2, cr2, cb3, cr3;
        chroma(x, y + 1, &cb2, &cr2);
        chroma(x + 1, y + 1, &cb3, &cr3);
        uint8_t* uv = &nv12[static_cast<size_t>(w) * h + static_cast<size_t>(y / 2) * w + x];
        uv[0] = Clamp((cb0 + cb1 + cb2 + cb3) / 4);
        uv[1] = Clamp((cr0 + cr1 + cr2 + cr3) / 4);
      }
    }
  }

  const ImageView<uint8_t> gray_out(w, h, w, gray.data());
  const ImageView<uint8_t> rgb_out(3 * w, h, 3 * w, rgb.data());
  ImageView<const uint8_t> gray_view, rgb_view;
  auto run = [&](RawFrameConverter* converter, PixelFormat format, const uint8_t* data, size_t size,
                 uint32_t pitch, const ImageView<uint8_t>& g, const ImageView<uint8_t>& c,
                 YuvRange range = YuvRange::kFull) {
    RawFrame raw;
    raw.layout = RawFrameLayout{format, format == PixelFormat::kMjpeg ? header->width : w,
                                format == PixelFormat::kMjpeg ? header->height : h, pitch, range};
    raw.data = data;
    raw.size = size;
    const Status status = converter->Convert(raw, "bench", g, c, &gray_view, &rgb_view);
    if (!status.ok()) std::fprintf(stderr, "%s\n", status.ToString().c_str());
  };
  RawFrameConverter with_rgb(FrameConversionSettings{true, GrayRange::kAsDelivered});
  RawFrameConverter gray_only(FrameConversionSettings{false, GrayRange::kAsDelivered});
  RawFrameConverter expanded(FrameConversionSettings{false, GrayRange::kFull});
  const auto* jpeg_bytes = reinterpret_cast<const uint8_t*>(jpeg.data());

  std::printf("%s (%dx%d), %d repetitions, ms per frame:\n", path.c_str(), w, h, repetitions);
  std::printf("  YUYV -> RGB + gray          %7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&with_rgb, PixelFormat::kYuyv, yuyv.data(), yuyv.size(), 2 * w, gray_out, rgb_out);
              }));
  std::printf("  YUYV -> gray                %7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&gray_only, PixelFormat::kYuyv, yuyv.data(), yuyv.size(), 2 * w, gray_out, rgb_out);
              }));
  std::printf("  NV12 -> RGB (gray zero-copy)%7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&with_rgb, PixelFormat::kNv12, nv12.data(), nv12.size(), w, gray_out, rgb_out);
              }));
  std::printf("  NV12 -> gray, limited range expanded %7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&expanded, PixelFormat::kNv12, nv12.data(), nv12.size(), w, gray_out, rgb_out, YuvRange::kLimited);
              }));
  std::printf("  MJPEG -> gray + RGB         %7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&with_rgb, PixelFormat::kMjpeg, jpeg_bytes, jpeg.size(), 0, gray_full, rgb_full);
              }));
  std::printf("  MJPEG -> gray only          %7.3f\n", MillisecondsPerCall(repetitions, [&] {
                run(&gray_only, PixelFormat::kMjpeg, jpeg_bytes, jpeg.size(), 0, gray_full, rgb_full);
              }));
  return 0;
}
