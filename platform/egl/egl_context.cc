#include "platform/egl/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES2/gl2.h>
#include <sys/stat.h>

#include <cstdlib>
#include <utility>
#include <vector>

#include "platform/egl/egl_util.h"
#include "platform/egl/native_output.h"

namespace reconar {
namespace {

bool DirectoryExists(const char* path) {
  struct stat info;
  return ::stat(path, &info) == 0 && S_ISDIR(info.st_mode);
}

EglContextKind ResolveKind(EglContextKind kind) {
  if (kind != EglContextKind::kAuto) return kind;
  if (HasX11Display()) return EglContextKind::kX11Window;
  if (DirectoryExists("/dev/dri")) return EglContextKind::kGbm;
  return EglContextKind::kSurfaceless;
}

// Picks a config for the context; with `visual_id` != 0 the config's EGL_NATIVE_VISUAL_ID must match.
Result<EGLConfig> ChooseConfig(EGLDisplay display, const EglContextOptions& options, bool window, EGLint visual_id) {
  const EGLint renderable = options.gles_version >= 3 ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_ES2_BIT;
  std::vector<EGLint> attributes = {EGL_RENDERABLE_TYPE, renderable, EGL_SURFACE_TYPE, window ? EGL_WINDOW_BIT : 0};
  if (window) {
    const EGLint color_depth[] = {EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_DEPTH_SIZE, 24};
    attributes.insert(attributes.end(), std::begin(color_depth), std::end(color_depth));
    if (options.samples > 0) {
      const EGLint multisample[] = {EGL_SAMPLE_BUFFERS, 1, EGL_SAMPLES, options.samples};
      attributes.insert(attributes.end(), std::begin(multisample), std::end(multisample));
    }
  }
  attributes.push_back(EGL_NONE);
  EGLint count = 0;
  if (eglChooseConfig(display, attributes.data(), nullptr, 0, &count) != EGL_TRUE) {
    return EglFailure(StatusCode::kFailedPrecondition, "EGL: eglChooseConfig failed");
  }
  std::vector<EGLConfig> configs(static_cast<size_t>(count));
  if (count > 0 && eglChooseConfig(display, attributes.data(), configs.data(), count, &count) != EGL_TRUE) {
    return EglFailure(StatusCode::kFailedPrecondition, "EGL: eglChooseConfig failed");
  }
  for (EGLint i = 0; i < count; ++i) {
    EGLint id = 0;
    eglGetConfigAttrib(display, configs[static_cast<size_t>(i)], EGL_NATIVE_VISUAL_ID, &id);
    if (visual_id == 0 || id == visual_id) return configs[static_cast<size_t>(i)];
  }
  return FailedPrecondition("EGL: no config for OpenGL ES " + std::to_string(options.gles_version) +
                            (window ? " with a window surface" : "") +
                            (options.samples > 0 ? " and " + std::to_string(options.samples) + " samples" : "") +
                            (visual_id != 0 ? " matching the native visual " + std::to_string(visual_id) : ""));
}

}  // namespace

const char* EglContextKindName(EglContextKind kind) {
  switch (kind) {
    case EglContextKind::kAuto:
      return "auto";
    case EglContextKind::kSurfaceless:
      return "surfaceless";
    case EglContextKind::kGbm:
      return "gbm";
    case EglContextKind::kX11Window:
      return "x11";
  }
  return "unknown";
}

Result<EglContextKind> OnScreenKindFromName(const std::string& name) {
  if (name == "auto") return EglContextKind::kAuto;
  if (name == "x11") return EglContextKind::kX11Window;
  if (name == "gbm") return EglContextKind::kGbm;
  return InvalidArgument("--window: '" + name + "' is not auto, x11 or gbm");
}

bool HasX11Display() {
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && display[0] != '\0';
}

Status EglContextOptions::Check() const {
  if (gles_version != 2 && gles_version != 3) {
    return InvalidArgument("EglContextOptions.gles_version must be 2 or 3, got " + std::to_string(gles_version));
  }
  if (width <= 0 || height <= 0) {
    return InvalidArgument("EglContextOptions.width/height must be positive, got " + std::to_string(width) + "x" +
                           std::to_string(height));
  }
  if (samples < 0) return InvalidArgument("EglContextOptions.samples must be >= 0");
  return Status::Ok();
}

struct EglContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;

  ~Egl() {
    if (display == EGL_NO_DISPLAY) return;
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
    if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
    eglTerminate(display);
    eglReleaseThread();
  }
};

EglContext::EglContext() : egl_(new Egl) {}
EglContext::~EglContext() {
  egl_.reset();  // the surface before the native window it draws into
  output_.reset();
}

Result<std::unique_ptr<EglContext>> EglContext::CreateOnScreen(const Options& options) {
  if (options.kind == EglContextKind::kSurfaceless) {
    return InvalidArgument("an on-screen EGL context cannot be surfaceless");
  }
  if (ResolveKind(options.kind) == EglContextKind::kSurfaceless) {
    return FailedPrecondition("DISPLAY is not set and there is no DRM device under /dev/dri");
  }
  return Create(options);
}

Result<std::unique_ptr<EglContext>> EglContext::Create(const Options& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::unique_ptr<EglContext> result(new EglContext);
  result->kind_ = ResolveKind(options.kind);
  Egl& egl = *result->egl_;

  if (result->kind_ == Kind::kSurfaceless) {
    RECONAR_ASSIGN_OR_RETURN(egl.display, OpenPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                                              "EGL_MESA_platform_surfaceless", nullptr));
    result->surfaceless_width_ = options.width;
    result->surfaceless_height_ = options.height;
  } else {
    if (result->kind_ == Kind::kGbm) {
      RECONAR_ASSIGN_OR_RETURN(result->output_, OpenKmsOutput(options.drm_device));
    } else {
      RECONAR_ASSIGN_OR_RETURN(result->output_, OpenX11Window(options.width, options.height, options.title));
    }
    NativeOutput& output = *result->output_;
    const bool gbm = result->kind_ == Kind::kGbm;
    RECONAR_ASSIGN_OR_RETURN(egl.display, OpenPlatformDisplay(output.platform(), output.native_display(),
                                                              gbm ? "EGL_KHR_platform_gbm" : "EGL_KHR_platform_x11",
                                                              gbm ? "EGL_MESA_platform_gbm" : "EGL_EXT_platform_x11"));
  }

  const bool window = result->output_ != nullptr;
  const EGLint visual_id = window ? result->output_->required_visual_id() : 0;
  RECONAR_ASSIGN_OR_RETURN(EGLConfig config, ChooseConfig(egl.display, options, window, visual_id));
  if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) {
    return EglFailure(StatusCode::kUnsupported, "EGL: eglBindAPI(EGL_OPENGL_ES_API) failed");
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, options.gles_version, EGL_NONE};
  egl.context = eglCreateContext(egl.display, config, EGL_NO_CONTEXT, context_attributes);
  if (egl.context == EGL_NO_CONTEXT) {
    return EglFailure(StatusCode::kFailedPrecondition,
                      "EGL: cannot create an OpenGL ES " + std::to_string(options.gles_version) + " context");
  }

  if (window) {
    EGLint config_visual = 0;
    eglGetConfigAttrib(egl.display, config, EGL_NATIVE_VISUAL_ID, &config_visual);
    RECONAR_RETURN_IF_ERROR(result->output_->CreateWindow(config_visual));
    auto create_window_surface = reinterpret_cast<PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC>(
        eglGetProcAddress("eglCreatePlatformWindowSurfaceEXT"));
    if (create_window_surface == nullptr) return Unsupported("EGL: eglCreatePlatformWindowSurfaceEXT is missing");
    egl.surface = create_window_surface(egl.display, config, result->output_->native_window(), nullptr);
    if (egl.surface == EGL_NO_SURFACE) {
      return EglFailure(StatusCode::kFailedPrecondition,
                        std::string("EGL: cannot create a window surface on ") + EglContextKindName(result->kind_));
    }
  } else if (!HasExtension(eglQueryString(egl.display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    return Unsupported("EGL: the surfaceless display lacks EGL_KHR_surfaceless_context");
  }
  RECONAR_RETURN_IF_ERROR(result->MakeCurrent());

  const char* vendor = eglQueryString(egl.display, EGL_VENDOR);
  const GLubyte* renderer = glGetString(GL_RENDERER);
  const GLubyte* version = glGetString(GL_VERSION);
  result->egl_vendor_ = vendor != nullptr ? vendor : "";
  result->renderer_ = renderer != nullptr ? reinterpret_cast<const char*>(renderer) : "";
  result->gl_version_ = version != nullptr ? reinterpret_cast<const char*>(version) : "";
  return result;
}

bool EglContext::has_surface() const { return egl_->surface != EGL_NO_SURFACE; }
int EglContext::width() const { return output_ ? output_->width() : surfaceless_width_; }
int EglContext::height() const { return output_ ? output_->height() : surfaceless_height_; }

Status EglContext::MakeCurrent() {
  if (eglMakeCurrent(egl_->display, egl_->surface, egl_->surface, egl_->context) != EGL_TRUE) {
    return EglFailure(StatusCode::kFailedPrecondition,
                      std::string("EGL: eglMakeCurrent on the ") + EglContextKindName(kind_) + " context failed");
  }
  return Status::Ok();
}

Status EglContext::SwapBuffers() {
  if (egl_->surface == EGL_NO_SURFACE) {
    glFinish();
    return Status::Ok();
  }
  if (eglSwapBuffers(egl_->display, egl_->surface) != EGL_TRUE) {
    return EglFailure(StatusCode::kIoError,
                      std::string("EGL: eglSwapBuffers on ") + EglContextKindName(kind_) + " failed");
  }
  return output_->Present();
}

WindowEvents EglContext::PollEvents() { return output_ ? output_->PollEvents() : WindowEvents(); }

#ifndef RECONAR_HAVE_GBM_DRM
Result<std::unique_ptr<NativeOutput>> OpenKmsOutput(const std::string&) {
  return Unsupported("EGL: the GBM/KMS route was not built (gbm and libdrm were not found at build time)");
}
#endif
#ifndef RECONAR_HAVE_X11
Result<std::unique_ptr<NativeOutput>> OpenX11Window(int, int, const std::string&) {
  return Unsupported("EGL: the X11 window route was not built (x11 was not found at build time)");
}
#endif

}  // namespace reconar
