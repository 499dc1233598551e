// GBM/KMS output: a GBM surface in the preferred mode of the first connected connector, scanned
// out with drmModeSetCrtc (first frame) and drmModePageFlip (later frames, waiting for the flip).
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dirent.h>
#include <fcntl.h>
#include <gbm.h>
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "platform/egl/native_output.h"
#include "platform/input/touch_input.h"

namespace reconar {
namespace {

constexpr const char* kDriDirectory = "/dev/dri";

std::vector<std::string> CardDevices() {
  std::vector<std::string> devices;
  DIR* dir = ::opendir(kDriDirectory);
  if (dir == nullptr) return devices;
  while (const dirent* entry = ::readdir(dir)) {
    if (std::strncmp(entry->d_name, "card", 4) == 0)
      devices.push_back(std::string(kDriDirectory) + "/" + entry->d_name);
  }
  ::closedir(dir);
  return devices;
}

// The mode, connector and CRTC that scan-out uses.
struct KmsPath {
  uint32_t connector_id = 0;
  uint32_t crtc_id = 0;
  drmModeModeInfo mode{};
};

Result<KmsPath> FindConnectedOutput(int fd, const std::string& device) {
  drmModeRes* resources = drmModeGetResources(fd);
  if (resources == nullptr) {
    return FailedPrecondition(device + ": drmModeGetResources failed (" + std::strerror(errno) +
                              "; a render node cannot do mode setting)");
  }
  KmsPath path;
  bool found = false;
  for (int i = 0; i < resources->count_connectors && !found; ++i) {
    drmModeConnector* connector = drmModeGetConnector(fd, resources->connectors[i]);
    if (connector == nullptr) continue;
    if (connector->connection == DRM_MODE_CONNECTED && connector->count_modes > 0) {
      path.connector_id = connector->connector_id;
      path.mode = connector->modes[0];
      for (int m = 0; m < connector->count_modes; ++m) {
        if (connector->modes[m].type & DRM_MODE_TYPE_PREFERRED) {
          path.mode = connector->modes[m];
          break;
        }
      }
      // The CRTC of the current encoder, else the first CRTC any of its encoders can drive.
      drmModeEncoder* encoder = connector->encoder_id ? drmModeGetEncoder(fd, connector->encoder_id) : nullptr;
      if (encoder != nullptr && encoder->crtc_id != 0) path.crtc_id = encoder->crtc_id;
      if (encoder != nullptr) drmModeFreeEncoder(encoder);
      for (int e = 0; e < connector->count_encoders && path.crtc_id == 0; ++e) {
        drmModeEncoder* candidate = drmModeGetEncoder(fd, connector->encoders[e]);
        if (candidate == nullptr) continue;
        for (int c = 0; c < resources->count_crtcs; ++c) {
          if (candidate->possible_crtcs & (1u << c)) {
            path.crtc_id = resources->crtcs[c];
            break;
          }
        }
        drmModeFreeEncoder(candidate);
      }
      found = path.crtc_id != 0;
    }
    drmModeFreeConnector(connector);
  }
  drmModeFreeResources(resources);
  if (!found) return FailedPrecondition(device + ": no connected connector with a mode and a usable CRTC");
  return path;
}

class KmsOutput final : public NativeOutput {
 public:
  KmsOutput(int fd, std::string device, const KmsPath& path) : fd_(fd), device_(std::move(device)), path_(path) {}
  ~KmsOutput() override {
    if (saved_crtc_ != nullptr) {
      drmModeSetCrtc(fd_, saved_crtc_->crtc_id, saved_crtc_->buffer_id, saved_crtc_->x, saved_crtc_->y,
                     &path_.connector_id, 1, &saved_crtc_->mode);
      drmModeFreeCrtc(saved_crtc_);
    }
    if (surface_ != nullptr) {
      if (front_ != nullptr) gbm_surface_release_buffer(surface_, front_);
      gbm_surface_destroy(surface_);
    }
    if (gbm_ != nullptr) gbm_device_destroy(gbm_);
    ::close(fd_);
  }

  Status Init() {
    gbm_ = gbm_create_device(fd_);
    if (gbm_ == nullptr) return FailedPrecondition(device_ + ": gbm_create_device failed");
    return Status::Ok();
  }

  EGLenum platform() const override { return EGL_PLATFORM_GBM_KHR; }
  void* native_display() const override { return gbm_; }
  EGLint required_visual_id() const override { return GBM_FORMAT_XRGB8888; }
  int width() const override { return path_.mode.hdisplay; }
  int height() const override { return path_.mode.vdisplay; }
  void* native_window() override { return surface_; }

  // A touch screen's taps, when there is one that can be read (else none: the view still runs).
  WindowEvents PollEvents() override {
    WindowEvents events;
    if (touch_ != nullptr) touch_->Poll(&events.taps);
    return events;
  }

  Status CreateWindow(EGLint) override {
    Result<std::unique_ptr<TouchInput>> touch = TouchInput::Open(width(), height());
    if (touch.ok()) touch_ = std::move(*touch);
    surface_ = gbm_surface_create(gbm_, path_.mode.hdisplay, path_.mode.vdisplay, GBM_FORMAT_XRGB8888,
                                  GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
    if (surface_ == nullptr) {
      return FailedPrecondition(device_ + ": gbm_surface_create " + std::to_string(width()) + "x" +
                                std::to_string(height()) + " XRGB8888 failed");
    }
    return Status::Ok();
  }

  Status Present() override {
    gbm_bo* next = gbm_surface_lock_front_buffer(surface_);
    if (next == nullptr) return IoError(device_ + ": gbm_surface_lock_front_buffer failed");
    Result<uint32_t> fb = FramebufferOf(next);
    if (!fb.ok()) {
      gbm_surface_release_buffer(surface_, next);
      return fb.status();
    }
    if (saved_crtc_ == nullptr) {
      saved_crtc_ = drmModeGetCrtc(fd_, path_.crtc_id);
      if (drmModeSetCrtc(fd_, path_.crtc_id, *fb, 0, 0, &path_.connector_id, 1, &path_.mode) != 0) {
        gbm_surface_release_buffer(surface_, next);
        return IoError(device_ + ": drmModeSetCrtc failed: " + std::strerror(errno));
      }
    } else {
      bool flipped = false;
      if (drmModePageFlip(fd_, path_.crtc_id, *fb, DRM_MODE_PAGE_FLIP_EVENT, &flipped) != 0) {
        gbm_surface_release_buffer(surface_, next);
        return IoError(device_ + ": drmModePageFlip failed: " + std::strerror(errno));
      }
      RECONAR_RETURN_IF_ERROR(WaitForFlip(&flipped));
    }
    if (front_ != nullptr) gbm_surface_release_buffer(surface_, front_);
    front_ = next;
    return Status::Ok();
  }

 private:
  static void OnPageFlip(int, unsigned, unsigned, unsigned, void* flipped) { *static_cast<bool*>(flipped) = true; }

  Status WaitForFlip(bool* flipped) {
    drmEventContext events{};
    events.version = 2;
    events.page_flip_handler = &KmsOutput::OnPageFlip;
    while (!*flipped) {
      pollfd waiting{fd_, POLLIN, 0};
      const int ready = ::poll(&waiting, 1, 1000);
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) return IoError(device_ + ": no page-flip event within 1 s");
      drmHandleEvent(fd_, &events);
    }
    return Status::Ok();
  }

  static void DestroyFramebuffer(gbm_bo* bo, void* data) {
    auto* fb = static_cast<std::pair<int, uint32_t>*>(data);
    drmModeRmFB(fb->first, fb->second);
    delete fb;
    (void)bo;
  }

  // The DRM framebuffer wrapping a GBM buffer, created once per buffer and kept as its user data.
  Result<uint32_t> FramebufferOf(gbm_bo* bo) {
    if (auto* cached = static_cast<std::pair<int, uint32_t>*>(gbm_bo_get_user_data(bo))) return cached->second;
    uint32_t fb_id = 0;
    if (drmModeAddFB(fd_, gbm_bo_get_width(bo), gbm_bo_get_height(bo), 24, 32, gbm_bo_get_stride(bo),
                     gbm_bo_get_handle(bo).u32, &fb_id) != 0) {
      return IoError(device_ + ": drmModeAddFB failed: " + std::strerror(errno));
    }
    gbm_bo_set_user_data(bo, new std::pair<int, uint32_t>(fd_, fb_id), &KmsOutput::DestroyFramebuffer);
    return fb_id;
  }

  int fd_;
  std::string device_;
  KmsPath path_;
  gbm_device* gbm_ = nullptr;
  gbm_surface* surface_ = nullptr;
  gbm_bo* front_ = nullptr;            // the buffer on screen, released after the next flip
  drmModeCrtc* saved_crtc_ = nullptr;  // the mode before ours, restored on destruction
  std::unique_ptr<TouchInput> touch_;
};

}  // namespace

Result<std::unique_ptr<NativeOutput>> OpenKmsOutput(const std::string& device) {
  std::vector<std::string> candidates;
  if (!device.empty()) {
    candidates.push_back(device);
  } else {
    candidates = CardDevices();
    if (candidates.empty()) return FailedPrecondition("EGL gbm: no DRM device under /dev/dri");
  }
  std::string reasons;
  for (const std::string& path : candidates) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
      reasons += (reasons.empty() ? "" : "; ") + path + ": cannot open: " + std::strerror(errno);
      continue;
    }
    Result<KmsPath> kms = FindConnectedOutput(fd, path);
    if (!kms.ok()) {
      ::close(fd);
      reasons += (reasons.empty() ? "" : "; ") + kms.status().message();
      continue;
    }
    auto output = std::make_unique<KmsOutput>(fd, path, *kms);
    RECONAR_RETURN_IF_ERROR(output->Init());
    return std::unique_ptr<NativeOutput>(std::move(output));
  }
  return FailedPrecondition("EGL gbm: no usable display output: " + reasons);
}

}  // namespace reconar
