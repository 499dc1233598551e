# FindIfcPlusPlus: IFC++ (Debian: libifcplusplus-dev; headers in /usr/include/ifcpp and
# /usr/include/carve, libraries in /usr/lib/ifcplusplus, not in the multiarch directory: a native
# build only). Result: IfcPlusPlus_FOUND and the imported target IfcPlusPlus::IfcPlusPlus (with
# its Carve geometry library).
find_path(IfcPlusPlus_INCLUDE_DIR ifcpp/reader/ReaderSTEP.h)
find_library(IfcPlusPlus_LIBRARY NAMES IfcPlusPlus PATH_SUFFIXES ifcplusplus)
find_library(IfcPlusPlus_CARVE_LIBRARY NAMES carve PATH_SUFFIXES ifcplusplus)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(IfcPlusPlus
  REQUIRED_VARS IfcPlusPlus_LIBRARY IfcPlusPlus_CARVE_LIBRARY IfcPlusPlus_INCLUDE_DIR)
mark_as_advanced(IfcPlusPlus_INCLUDE_DIR IfcPlusPlus_LIBRARY IfcPlusPlus_CARVE_LIBRARY)

if(IfcPlusPlus_FOUND AND NOT TARGET IfcPlusPlus::IfcPlusPlus)
  add_library(IfcPlusPlus::IfcPlusPlus UNKNOWN IMPORTED)
  set_target_properties(IfcPlusPlus::IfcPlusPlus PROPERTIES
    IMPORTED_LOCATION "${IfcPlusPlus_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${IfcPlusPlus_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${IfcPlusPlus_CARVE_LIBRARY}")
endif()
