// JPEG decoding with libjpeg-turbo. libjpeg reports fatal errors through error_exit, which must
// not return; ours longjmps back to the phase function that called setjmp. Those phase functions
// hold only trivially destructible state, so the jump skips no C++ destructors.
#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <jpeglib.h>
#include <jerror.h>

#include "core/io/decoders.h"

namespace reconar::io_internal {

namespace {

constexpr int kMaxKeptWarnings = 4;
constexpr int kMaxRowsPerCall = 16;

enum class Failure { kNone, kError, kTruncated, kCorruptScan };
enum class Phase { kHeader, kScanlines, kFinish };

struct ErrorManager {
  jpeg_error_mgr pub;  // first member: libjpeg hands back a jpeg_error_mgr*
  std::jmp_buf jump;
  Phase phase;
  Failure failure;
  int msg_code;
  JDIMENSION rows_at_failure;
  int scan_at_failure;
  char message[JMSG_LENGTH_MAX];
  int warning_count;
  char warnings[kMaxKeptWarnings][JMSG_LENGTH_MAX];
};

ErrorManager* GetManager(j_common_ptr cinfo) { return reinterpret_cast<ErrorManager*>(cinfo->err); }

// Which libjpeg warnings mean the pixels are wrong. libjpeg itself only warns and fills the
// rest of the image with grey, which would silently feed garbage to feature detection.
Failure ClassifyWarning(int code, int marker) {
  switch (code) {
    case JWRN_JPEG_EOF:
      return Failure::kTruncated;
    case JWRN_HIT_MARKER:
    case JWRN_HUFF_BAD_CODE:
    case JWRN_MUST_RESYNC:
    case JWRN_NOT_SEQUENTIAL:
    case JWRN_BOGUS_PROGRESSION:
#if JPEG_LIB_VERSION >= 70 || defined(D_ARITH_CODING_SUPPORTED)
    case JWRN_ARITH_BAD_CODE:
#endif
      return Failure::kCorruptScan;
    case JWRN_EXTRANEOUS_DATA:
      // Junk before a restart marker means a damaged restart interval; before other markers
      // (typically EOI) it is harmless padding that many encoders leave behind.
      return (marker >= 0xD0 && marker <= 0xD7) ? Failure::kCorruptScan : Failure::kNone;
    default:
      return Failure::kNone;
  }
}

[[noreturn]] void FailAndJump(j_common_ptr cinfo, Failure failure) {
  ErrorManager* err = GetManager(cinfo);
  (*cinfo->err->format_message)(cinfo, err->message);
  err->failure = failure;
  err->msg_code = cinfo->err->msg_code;
  if (cinfo->is_decompressor) {
    const auto* dinfo = reinterpret_cast<j_decompress_ptr>(cinfo);
    err->rows_at_failure = dinfo->output_scanline;
    err->scan_at_failure = dinfo->input_scan_number;
  }
  std::longjmp(err->jump, 1);
}

[[noreturn]] void OnError(j_common_ptr cinfo) { FailAndJump(cinfo, Failure::kError); }

void OnMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;  // trace output
  ErrorManager* err = GetManager(cinfo);
  const Failure failure = ClassifyWarning(cinfo->err->msg_code, cinfo->err->msg_parm.i[1]);
  // Once every row is out, problems in the trailer do not affect the pixels.
  if (failure != Failure::kNone && err->phase != Phase::kFinish) FailAndJump(cinfo, failure);
  if (err->warning_count < kMaxKeptWarnings) {
    (*cinfo->err->format_message)(cinfo, err->warnings[err->warning_count]);
  }
  ++err->warning_count;
}

void OnOutputMessage(j_common_ptr) {}  // never print to stderr; messages come back in Status

// Like jpeg_mem_src, but running out of data is recorded instead of warned about. libjpeg
// prefetches entropy-coded bytes, so a stream that merely lacks its EOI marker also runs dry;
// only when the decoder then actually needs missing bits (JWRN_HIT_MARKER) are pixels lost.
struct MemorySource {
  jpeg_source_mgr pub;  // first member: libjpeg hands back a jpeg_source_mgr*
  bool exhausted;
};

const JOCTET kFakeEoi[2] = {0xFF, JPEG_EOI};

void InitSource(j_decompress_ptr) {}
void TermSource(j_decompress_ptr) {}

boolean FillInputBuffer(j_decompress_ptr cinfo) {
  auto* src = reinterpret_cast<MemorySource*>(cinfo->src);
  src->exhausted = true;
  src->pub.next_input_byte = kFakeEoi;
  src->pub.bytes_in_buffer = sizeof(kFakeEoi);
  return TRUE;
}

void SkipInputData(j_decompress_ptr cinfo, long num_bytes) {
  if (num_bytes <= 0) return;
  auto* src = reinterpret_cast<MemorySource*>(cinfo->src);
  if (static_cast<unsigned long>(num_bytes) > src->pub.bytes_in_buffer) {
    FillInputBuffer(cinfo);  // skipping past the end: leave the fake EOI to be read
    return;
  }
  src->pub.next_input_byte += num_bytes;
  src->pub.bytes_in_buffer -= static_cast<size_t>(num_bytes);
}

void SetMemorySource(j_decompress_ptr cinfo, MemorySource* src, const unsigned char* data, size_t size) {
  src->pub.init_source = InitSource;
  src->pub.fill_input_buffer = FillInputBuffer;
  src->pub.skip_input_data = SkipInputData;
  src->pub.resync_to_restart = jpeg_resync_to_restart;
  src->pub.term_source = TermSource;
  src->pub.next_input_byte = data;
  src->pub.bytes_in_buffer = size;
  src->exhausted = false;
  cinfo->src = &src->pub;
}

struct HeaderInfo {
  JDIMENSION width;
  JDIMENSION height;
  J_COLOR_SPACE color_space;
  int components;
};

bool ReadHeader(j_decompress_ptr cinfo, ErrorManager* err, MemorySource* src, const unsigned char* data,
                size_t size, HeaderInfo* header) {
  err->phase = Phase::kHeader;
  if (setjmp(err->jump)) return false;
  jpeg_create_decompress(cinfo);
  SetMemorySource(cinfo, src, data, size);
  jpeg_save_markers(cinfo, JPEG_APP0 + 1, 0xFFFF);
  jpeg_read_header(cinfo, TRUE);
  header->width = cinfo->image_width;
  header->height = cinfo->image_height;
  header->color_space = cinfo->jpeg_color_space;
  header->components = cinfo->num_components;
  return true;
}

// In a progressive JPEG, whether every coefficient of every component got all its bits.
bool AllCoefficientsComplete(j_decompress_ptr cinfo) {
  if (cinfo->coef_bits == nullptr) return true;
  for (int c = 0; c < cinfo->num_components; ++c) {
    for (int k = 0; k < DCTSIZE2; ++k) {
      if (cinfo->coef_bits[c][k] != 0) return false;
    }
  }
  return true;
}

// Decodes straight into `pixels` (width*3 bytes per row). Returns false with err->failure set.
bool DecodeScanlines(j_decompress_ptr cinfo, ErrorManager* err, uint8_t* pixels, JDIMENSION width,
                     JDIMENSION height) {
  err->phase = Phase::kScanlines;
  if (setjmp(err->jump)) return false;
  cinfo->out_color_space = JCS_RGB;
  cinfo->dct_method = JDCT_ISLOW;
  jpeg_start_decompress(cinfo);
  if (cinfo->output_width != width || cinfo->output_height != height || cinfo->output_components != 3) {
    std::snprintf(err->message, sizeof(err->message), "unexpected decoder output %ux%u with %d channels",
                  static_cast<unsigned>(cinfo->output_width), static_cast<unsigned>(cinfo->output_height),
                  cinfo->output_components);
    err->failure = Failure::kError;
    err->msg_code = 0;
    return false;
  }
  if (cinfo->progressive_mode && reinterpret_cast<MemorySource*>(cinfo->src)->exhausted &&
      !AllCoefficientsComplete(cinfo)) {
    // The data ended exactly between two scans: no decoder warning, but refinements are missing.
    err->failure = Failure::kTruncated;
    err->rows_at_failure = 0;
    err->scan_at_failure = cinfo->input_scan_number;
    return false;
  }
  const size_t row_bytes = static_cast<size_t>(width) * 3;
  JSAMPROW rows[kMaxRowsPerCall];
  while (cinfo->output_scanline < height) {
    const JDIMENSION first = cinfo->output_scanline;
    const JDIMENSION count = std::min<JDIMENSION>(kMaxRowsPerCall, height - first);
    for (JDIMENSION i = 0; i < count; ++i) rows[i] = pixels + (first + i) * row_bytes;
    jpeg_read_scanlines(cinfo, rows, count);
  }
  err->phase = Phase::kFinish;
  jpeg_finish_decompress(cinfo);
  return true;
}

Status FailureToStatus(const ErrorManager& err, const MemorySource& src, const std::string& name, JDIMENSION height,
                       bool progressive) {
  const std::string rows = std::to_string(err.rows_at_failure) + " of " + std::to_string(height) + " rows";
  // Whatever libjpeg complained about, if the data had run out, the cause is truncation.
  const Failure failure = src.exhausted ? Failure::kTruncated : err.failure;
  switch (failure) {
    case Failure::kTruncated:
      if (err.phase == Phase::kHeader) {
        return FileError(StatusCode::kCorruptData, name, "truncated JPEG data (ends inside the headers)");
      }
      if (progressive && err.rows_at_failure == 0) {
        return FileError(StatusCode::kCorruptData, name,
                         "truncated JPEG data (ends in scan " + std::to_string(err.scan_at_failure) +
                             " of a progressive image)");
      }
      return FileError(StatusCode::kCorruptData, name, "truncated JPEG data (got " + rows + ")");
    case Failure::kCorruptScan:
      return FileError(StatusCode::kCorruptData, name,
                       "corrupt JPEG scan data after " + rows + " (" + err.message + ")");
    case Failure::kError:
    case Failure::kNone:
      break;
  }
  switch (err.msg_code) {
    case JERR_OUT_OF_MEMORY:
    case JERR_IMAGE_TOO_BIG:
      return FileError(StatusCode::kResourceExhausted, name, std::string("JPEG too large to decode: ") + err.message);
    case JERR_BAD_PRECISION:
    case JERR_CONVERSION_NOTIMPL:
      return FileError(StatusCode::kUnsupported, name, std::string("unsupported JPEG: ") + err.message);
    default:
      return FileError(StatusCode::kCorruptData, name, std::string("invalid JPEG data: ") + err.message);
  }
}

// One decompression of a JPEG in memory: the error manager that records instead of exiting, the
// source, the header once read. The decompressor is destroyed however it ended (jpeg_destroy is
// safe on a zeroed struct).
class Decompression {
 public:
  Decompression() {
    cinfo.err = jpeg_std_error(&err.pub);
    err.pub.error_exit = OnError;
    err.pub.emit_message = OnMessage;
    err.pub.output_message = OnOutputMessage;
  }
  ~Decompression() { jpeg_destroy_decompress(&cinfo); }
  Decompression(const Decompression&) = delete;
  Decompression& operator=(const Decompression&) = delete;

  Status ReadHeaderOf(std::string_view bytes, const std::string& name) {
    if (!ReadHeader(&cinfo, &err, &src, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), &header)) {
      return FailureToStatus(err, src, name, 0, false);
    }
    return Status::Ok();
  }

  ErrorManager err{};
  jpeg_decompress_struct cinfo{};
  MemorySource src{};
  HeaderInfo header{};
};

// The EXIF of the APP1 markers ReadHeader saved.
ExifInfo SavedExif(const jpeg_decompress_struct& cinfo, std::vector<std::string>* warnings) {
  for (jpeg_saved_marker_ptr marker = cinfo.marker_list; marker != nullptr; marker = marker->next) {
    const std::string_view payload(reinterpret_cast<const char*>(marker->data), marker->data_length);
    if (marker->marker == JPEG_APP0 + 1 && payload.size() >= 5 && payload.substr(0, 5) == std::string_view("Exif\0", 5)) {
      ExifInfo exif = ParseExifApp1(payload);
      if (!exif.warning.empty() && warnings != nullptr) warnings->push_back("EXIF: " + exif.warning);
      return exif;
    }
  }
  return ExifInfo{};
}

}  // namespace

Status ReadJpegHeader(std::string_view bytes, const std::string& name, ImageHeader* out) {
  Decompression decompression;
  RECONAR_RETURN_IF_ERROR(decompression.ReadHeaderOf(bytes, name));
  out->width = static_cast<int>(decompression.header.width);
  out->height = static_cast<int>(decompression.header.height);
  out->exif = SavedExif(decompression.cinfo, nullptr);
  return Status::Ok();
}

Status DecodeJpeg(std::string_view bytes, const std::string& name, const ImageReadOptions& options,
                  DecodedImage* out) {
  Decompression decompression;
  RECONAR_RETURN_IF_ERROR(decompression.ReadHeaderOf(bytes, name));
  ErrorManager& err = decompression.err;
  jpeg_decompress_struct& cinfo = decompression.cinfo;
  const MemorySource& src = decompression.src;
  const HeaderInfo& header = decompression.header;
  if (header.color_space == JCS_CMYK || header.color_space == JCS_YCCK) {
    return FileError(StatusCode::kUnsupported, name, "CMYK JPEG is not supported; convert to RGB");
  }
  if (header.color_space != JCS_GRAYSCALE && header.color_space != JCS_RGB && header.color_space != JCS_YCbCr) {
    return FileError(StatusCode::kUnsupported, name,
                     "JPEG with " + std::to_string(header.components) +
                         " components in an unknown colour space is not supported");
  }
  RECONAR_RETURN_IF_ERROR(CheckDimensions(header.width, header.height, name, options));

  out->exif = SavedExif(cinfo, &out->warnings);

  out->rgb = Image<uint8_t>(static_cast<int>(header.width), static_cast<int>(header.height), 3);
  if (!DecodeScanlines(&cinfo, &err, out->rgb.data(), header.width, header.height)) {
    if (err.phase != Phase::kFinish) {
      out->rgb = Image<uint8_t>();
      return FailureToStatus(err, src, name, header.height, cinfo.progressive_mode != 0);
    }
    // Every row was already decoded; a damaged trailer does not change the pixels.
    out->warnings.push_back(std::string("JPEG: after the last row: ") + err.message);
  }
  if (src.exhausted) out->warnings.push_back("JPEG: data ends without an EOI marker");
  for (int i = 0; i < std::min(err.warning_count, kMaxKeptWarnings); ++i) {
    out->warnings.push_back(std::string("JPEG: ") + err.warnings[i]);
  }
  if (err.warning_count > kMaxKeptWarnings) {
    out->warnings.push_back("JPEG: " + std::to_string(err.warning_count - kMaxKeptWarnings) + " more warnings");
  }
  return Status::Ok();
}

}  // namespace reconar::io_internal
