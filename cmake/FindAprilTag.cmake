# FindAprilTag: libapriltag (AprilRobotics, Debian libapriltag-dev 3.3) as imported target
# AprilTag::AprilTag, linking libapriltag + libapriltag-utils (image_u8_*, which apriltag.pc omits) + m.
#
# Cross builds: libapriltag-dev:arm64 cannot be co-installed with the amd64 package (both ship
# /usr/share/apriltag/cmake/apriltagTargets-none.cmake), so only the runtime libapriltag3:arm64 is
# present. Its libraries are found by full name (libapriltag.so.3, libapriltag-utils.so.3) and the
# headers, which are architecture independent, are taken from /usr/include/apriltag.
#
# Sets AprilTag_FOUND, AprilTag_INCLUDE_DIR, AprilTag_LIBRARY, AprilTag_UTILS_LIBRARY.
include(FindPackageHandleStandardArgs)

find_path(AprilTag_INCLUDE_DIR NAMES apriltag/apriltag.h apriltag/apriltag_pose.h
          PATHS /usr/include /usr/local/include)
find_library(AprilTag_LIBRARY NAMES apriltag libapriltag.so.3)
find_library(AprilTag_UTILS_LIBRARY NAMES apriltag-utils libapriltag-utils.so.3)
find_library(AprilTag_MATH_LIBRARY NAMES m)

find_package_handle_standard_args(AprilTag
  REQUIRED_VARS AprilTag_LIBRARY AprilTag_UTILS_LIBRARY AprilTag_INCLUDE_DIR)

if(AprilTag_FOUND AND NOT TARGET AprilTag::AprilTag)
  add_library(AprilTag::AprilTag UNKNOWN IMPORTED GLOBAL)
  # The headers include each other as "common/..." and "apriltag.h", so both directories are needed.
  set_target_properties(AprilTag::AprilTag PROPERTIES
    IMPORTED_LOCATION "${AprilTag_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${AprilTag_INCLUDE_DIR};${AprilTag_INCLUDE_DIR}/apriltag")
  set(_apriltag_links "${AprilTag_UTILS_LIBRARY}")
  if(AprilTag_MATH_LIBRARY)
    list(APPEND _apriltag_links "${AprilTag_MATH_LIBRARY}")
  endif()
  set_property(TARGET AprilTag::AprilTag PROPERTY INTERFACE_LINK_LIBRARIES "${_apriltag_links}")
  unset(_apriltag_links)
endif()

mark_as_advanced(AprilTag_INCLUDE_DIR AprilTag_LIBRARY AprilTag_UTILS_LIBRARY AprilTag_MATH_LIBRARY)
