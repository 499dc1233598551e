#pragma once
// A surfaceless GLES 3 context shared by the GL tests of one executable (created on first use,
// current on the main thread, which runs every test).
#include <gtest/gtest.h>

#include <memory>

#include "platform/egl/egl_context.h"

namespace reconar {
namespace testing {

inline EglContext* SharedSurfacelessContext() {
  static std::unique_ptr<EglContext> context = [] {
    EglContextOptions options;
    options.kind = EglContextKind::kSurfaceless;
    auto created = EglContext::Create(options);
    if (!created.ok()) {
      ADD_FAILURE() << created.status().ToString();
      return std::unique_ptr<EglContext>();
    }
    return std::move(created).value();
  }();
  return context.get();
}

}  // namespace testing
}  // namespace reconar
