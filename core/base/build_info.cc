#include "core/base/build_info.h"

// Set for this file only by core/base/CMakeLists.txt, so that a new version recompiles one file.
#if !defined(RECONAR_VERSION) || !defined(RECONAR_BUILD_TYPE)
#error "build_info.cc needs RECONAR_VERSION and RECONAR_BUILD_TYPE from core/base/CMakeLists.txt"
#endif

namespace reconar {

const char* ReconarVersion() { return RECONAR_VERSION; }

const char* ReconarBuildType() {
  static constexpr char kBuildType[] = RECONAR_BUILD_TYPE;
  return kBuildType[0] != '\0' ? kBuildType : "unspecified";
}

}  // namespace reconar
