#pragma once
// What this build is: the CMake project version and the build type (configuration), for
// `reconar --version` and reports.
namespace reconar {

const char* ReconarVersion();    // "0.1.0" (project(reconar VERSION ...) in CMakeLists.txt)
const char* ReconarBuildType();  // "Release", "Debug", ...; "unspecified" when CMake had none

}  // namespace reconar
