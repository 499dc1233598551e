// JPEG encoding with libjpeg(-turbo). libjpeg reports fatal errors through error_exit, which
// longjmps back to EncodeJpeg; the state between setjmp and the jump is trivially destructible or
// owned by libjpeg (freed by jpeg_destroy_compress), so no destructor is skipped.
// jpeglib.h needs size_t and FILE declared before it.
// clang-format off
#include <csetjmp>
#include <cstdio>
#include <cstdlib>

#include <jpeglib.h>
#include <jerror.h>
// clang-format on

#include "core/base/atomic_file.h"
#include "core/io/image_write.h"

namespace reconar {
namespace {

struct JpegErrorManager {
  jpeg_error_mgr pub;  // first member: libjpeg hands back a jpeg_error_mgr*
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void OnJpegError(j_common_ptr cinfo) {
  auto* manager = reinterpret_cast<JpegErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, manager->message);
  std::longjmp(manager->jump, 1);
}

void IgnoreJpegMessage(j_common_ptr, int) {}

}  // namespace

Result<std::string> EncodeJpeg(ImageView<const uint8_t> interleaved, int channels, int quality,
                               const std::string& app1_payload) {
  if (channels != 1 && channels != 3) return InvalidArgument("EncodeJpeg: channels must be 1 or 3");
  if (interleaved.data == nullptr || interleaved.width <= 0 || interleaved.height <= 0 ||
      interleaved.width % channels != 0)
    return InvalidArgument("EncodeJpeg: an empty image or a width that is not a multiple of the channels");
  if (quality < 1 || quality > 100) return InvalidArgument("EncodeJpeg: quality must be in [1, 100]");
  if (app1_payload.size() > 65533) return InvalidArgument("EncodeJpeg: an APP1 payload over 65533 bytes");
  jpeg_compress_struct cinfo;
  JpegErrorManager errors;
  cinfo.err = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = OnJpegError;
  errors.pub.emit_message = IgnoreJpegMessage;
  errors.message[0] = '\0';
  unsigned char* buffer = nullptr;
  unsigned long size = 0;  // NOLINT(runtime/int): libjpeg's type
  if (setjmp(errors.jump) != 0) {
    jpeg_destroy_compress(&cinfo);
    std::free(buffer);
    return Internal(std::string("JPEG encoder: ") + errors.message);
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = static_cast<JDIMENSION>(interleaved.width / channels);
  cinfo.image_height = static_cast<JDIMENSION>(interleaved.height);
  cinfo.input_components = channels;
  cinfo.in_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  if (!app1_payload.empty()) {
    jpeg_write_marker(&cinfo, JPEG_APP0 + 1, reinterpret_cast<const JOCTET*>(app1_payload.data()),
                      static_cast<unsigned int>(app1_payload.size()));
  }
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(interleaved.row(static_cast<int>(cinfo.next_scanline)));
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  std::string bytes(reinterpret_cast<const char*>(buffer), size);
  jpeg_destroy_compress(&cinfo);
  std::free(buffer);
  return bytes;
}

Status WriteJpeg(const std::string& path, ImageView<const uint8_t> interleaved, int channels, int quality,
                 const std::string& app1_payload) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, EncodeJpeg(interleaved, channels, quality, app1_payload));
  return WriteFileAtomically(path, bytes);
}

}  // namespace reconar
