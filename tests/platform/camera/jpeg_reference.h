#pragma once
// Test-only reference decoding with libjpeg itself (independent of platform/camera's code):
// the JPEG's own Y/Cb/Cr planes through raw-data output, libjpeg's RGB / gray decode, and
// packing of 4:2:0 planes into the NV12 and YUYV layouts a camera delivers.
#include <cstdint>
#include <string>
#include <vector>

namespace reconar::testing {

struct YcbcrPlanes {
  int width = 0;
  int height = 0;
  int chroma_width = 0;   // ceil(width / 2) for 4:2:0
  int chroma_height = 0;  // ceil(height / 2) for 4:2:0
  int y_pitch = 0;        // padded to whole DCT blocks
  int chroma_pitch = 0;
  std::vector<uint8_t> y, cb, cr;
};

std::string ReadFileBytes(const std::string& path);

// libjpeg raw-data output (raw_data_out = TRUE, jpeg_read_raw_data). Returns false (with a
// reason) unless the JPEG is 3-component YCbCr with 4:2:0 sampling (Y 2x2, Cb/Cr 1x1).
bool ReadYcbcr420Planes(const std::string& jpeg, YcbcrPlanes* planes, std::string* reason);

// libjpeg's own decode: out_components 3 (JCS_RGB) or 1 (JCS_GRAYSCALE), tightly packed.
std::vector<uint8_t> LibjpegDecode(const std::string& jpeg, int out_components, bool fancy_upsampling,
                                   int* width = nullptr, int* height = nullptr);

// Encodes tightly packed RGB as a baseline 4:2:0 JFIF at `quality`.
std::string LibjpegEncodeRgb(const std::vector<uint8_t>& rgb, int width, int height, int quality);

// Camera layouts from 4:2:0 planes (chroma rows duplicated for YUYV's 4:2:2). Rows are
// `pitch` bytes apart; padding bytes are filled with 0xAB so that reading them shows.
std::vector<uint8_t> PackNv12(const YcbcrPlanes& planes, int pitch);
std::vector<uint8_t> PackYuyv(const YcbcrPlanes& planes, int pitch);

}  // namespace reconar::testing
