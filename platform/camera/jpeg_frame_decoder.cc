// libjpeg reports fatal errors through error_exit, which must not return: ours longjmps back to
// the function that called setjmp. Those functions hold only trivially destructible locals, so
// the jump skips no destructor. Corrupt-data warnings are turned into errors the same way.
#include "platform/camera/jpeg_frame_decoder.h"

#include <csetjmp>
#include <cstdio>
#include <string>

#include <jpeglib.h>
#include <jerror.h>

#include "platform/camera/pixel_convert.h"

namespace reconar {

namespace {

struct ErrorHandler {
  jpeg_error_mgr manager;  // first member: libjpeg passes back a jpeg_error_mgr*
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void FailWithMessage(j_common_ptr cinfo) {
  auto* handler = reinterpret_cast<ErrorHandler*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, handler->message);
  std::longjmp(handler->jump, 1);
}

void OnMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;  // trace output
  // Warnings mean lost or invented pixels (premature end, bad Huffman code, ...), except junk
  // bytes before the EOI marker, which many camera encoders leave behind.
  if (cinfo->err->msg_code == JWRN_EXTRANEOUS_DATA && cinfo->err->msg_parm.i[1] == JPEG_EOI) return;
  FailWithMessage(cinfo);
}

void Silent(j_common_ptr) {}

}  // namespace

struct JpegFrameDecoder::State {
  jpeg_decompress_struct cinfo{};
  ErrorHandler errors{};
};

JpegFrameDecoder::JpegFrameDecoder() : state_(std::make_unique<State>()) {
  state_->cinfo.err = jpeg_std_error(&state_->errors.manager);
  state_->errors.manager.error_exit = FailWithMessage;
  state_->errors.manager.emit_message = OnMessage;
  state_->errors.manager.output_message = Silent;
  jpeg_create_decompress(&state_->cinfo);
}

JpegFrameDecoder::~JpegFrameDecoder() { jpeg_destroy_decompress(&state_->cinfo); }

namespace {

// Phase functions: return false after a longjmp with the message in errors->message.
bool ReadHeaderPhase(jpeg_decompress_struct* cinfo, ErrorHandler* errors, const uint8_t* data, size_t size) {
  if (setjmp(errors->jump)) return false;
  jpeg_mem_src(cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(cinfo, TRUE);
  return true;
}

bool DecodeRowsPhase(jpeg_decompress_struct* cinfo, ErrorHandler* errors, J_COLOR_SPACE out_space,
                     const ImageView<uint8_t>& out) {
  if (setjmp(errors->jump)) return false;
  cinfo->out_color_space = out_space;
  jpeg_start_decompress(cinfo);
  const int components = out_space == JCS_GRAYSCALE ? 1 : 3;
  if (static_cast<int>(cinfo->output_width) * components != out.width ||
      static_cast<int>(cinfo->output_height) != out.height || cinfo->output_components != components) {
    std::snprintf(errors->message, sizeof(errors->message), "decoder output %ux%ux%d does not fit the buffer",
                  static_cast<unsigned>(cinfo->output_width), static_cast<unsigned>(cinfo->output_height),
                  cinfo->output_components);
    return false;
  }
  while (cinfo->output_scanline < cinfo->output_height) {
    JSAMPROW row = out.row(static_cast<int>(cinfo->output_scanline));
    jpeg_read_scanlines(cinfo, &row, 1);
  }
  jpeg_finish_decompress(cinfo);
  return true;
}

Status JpegError(std::string_view name, const char* message) {
  return Status(StatusCode::kCorruptData, std::string(name) + ": invalid JPEG data: " + message);
}

}  // namespace

Result<JpegHeader> JpegFrameDecoder::ReadHeader(const uint8_t* data, size_t size, std::string_view name) {
  jpeg_decompress_struct* cinfo = &state_->cinfo;
  const bool ok = ReadHeaderPhase(cinfo, &state_->errors, data, size);
  JpegHeader header;
  header.width = static_cast<int>(cinfo->image_width);
  header.height = static_cast<int>(cinfo->image_height);
  header.components = cinfo->num_components;
  jpeg_abort_decompress(cinfo);
  if (!ok) return JpegError(name, state_->errors.message);
  return header;
}

Status JpegFrameDecoder::Decode(const uint8_t* data, size_t size, std::string_view name,
                                const ImageView<uint8_t>& gray, const ImageView<uint8_t>& rgb) {
  jpeg_decompress_struct* cinfo = &state_->cinfo;
  ErrorHandler* errors = &state_->errors;
  if (!ReadHeaderPhase(cinfo, errors, data, size)) {
    jpeg_abort_decompress(cinfo);
    return JpegError(name, errors->message);
  }
  if (static_cast<int>(cinfo->image_width) != gray.width || static_cast<int>(cinfo->image_height) != gray.height) {
    const std::string size_text = std::to_string(cinfo->image_width) + "x" + std::to_string(cinfo->image_height);
    jpeg_abort_decompress(cinfo);
    return Status(StatusCode::kCorruptData, std::string(name) + ": JPEG is " + size_text + ", expected " +
                                                std::to_string(gray.width) + "x" + std::to_string(gray.height));
  }
  const J_COLOR_SPACE stored = cinfo->jpeg_color_space;
  if (stored != JCS_YCbCr && stored != JCS_GRAYSCALE && stored != JCS_RGB) {
    jpeg_abort_decompress(cinfo);
    return Status(StatusCode::kUnsupported, std::string(name) + ": JPEG colour space " + std::to_string(stored) +
                                                " (CMYK/YCCK) is not supported");
  }
  bool ok = true;
  if (rgb.empty() || stored == JCS_GRAYSCALE) {
    ok = DecodeRowsPhase(cinfo, errors, JCS_GRAYSCALE, gray);
    if (ok && !rgb.empty()) GrayToRgb(gray, rgb);
  } else if (stored == JCS_RGB) {
    ok = DecodeRowsPhase(cinfo, errors, JCS_RGB, rgb);
    if (ok) RgbToGray(rgb, gray);
  } else {
    // Y,Cb,Cr straight into the RGB buffer, then luma out and RGB converted in place.
    ok = DecodeRowsPhase(cinfo, errors, JCS_YCbCr, rgb);
    if (ok) {
      ExtractYcbcrLuma(rgb, gray);
      YcbcrToRgb(rgb, YuvConversionOptions{YuvRange::kFull}, rgb);
    }
  }
  if (!ok) {
    jpeg_abort_decompress(cinfo);
    return JpegError(name, errors->message);
  }
  return Status::Ok();
}

}  // namespace reconar
