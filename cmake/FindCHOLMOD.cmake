# FindCHOLMOD: the CHOLMOD sparse Cholesky library of SuiteSparse (Debian: libsuitesparse-dev,
# headers in /usr/include/suitesparse, libraries in the multiarch directory, so the aarch64
# toolchain finds libsuitesparse-dev:arm64 through CMAKE_LIBRARY_ARCHITECTURE).
#
# Result: CHOLMOD_FOUND, CHOLMOD_VERSION and the imported target CHOLMOD::CHOLMOD (include
# directory is the one holding cholmod.h, so sources say #include <cholmod.h>).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY NAMES cholmod)
find_library(CHOLMOD_SUITESPARSECONFIG_LIBRARY NAMES suitesparseconfig)

if(CHOLMOD_INCLUDE_DIR AND EXISTS "${CHOLMOD_INCLUDE_DIR}/cholmod_core.h")
  file(STRINGS "${CHOLMOD_INCLUDE_DIR}/cholmod_core.h" _cholmod_version_lines
       REGEX "^#define CHOLMOD_(MAIN|SUB|SUBSUB)_VERSION +[0-9]+")
  foreach(_part MAIN SUB SUBSUB)
    string(REGEX REPLACE ".*#define CHOLMOD_${_part}_VERSION +([0-9]+).*" "\\1" _cholmod_${_part}
           "${_cholmod_version_lines}")
  endforeach()
  set(CHOLMOD_VERSION "${_cholmod_MAIN}.${_cholmod_SUB}.${_cholmod_SUBSUB}")
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CHOLMOD
  REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_SUITESPARSECONFIG_LIBRARY CHOLMOD_INCLUDE_DIR
  VERSION_VAR CHOLMOD_VERSION)
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY CHOLMOD_SUITESPARSECONFIG_LIBRARY)

if(CHOLMOD_FOUND AND NOT TARGET CHOLMOD::CHOLMOD)
  add_library(CHOLMOD::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(CHOLMOD::CHOLMOD PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${CHOLMOD_SUITESPARSECONFIG_LIBRARY}")
endif()
