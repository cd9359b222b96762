# ADOL-C (Debian's libadolc-dev) ships a pkg-config file whose Libs name -lboost_system, a
# library Debian no longer builds; find the header and the library directly instead.
# Defines ADOLC::ADOLC.
find_path(ADOLC_INCLUDE_DIR adolc/adolc.h)
find_library(ADOLC_LIBRARY adolc)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(ADOLC REQUIRED_VARS ADOLC_LIBRARY ADOLC_INCLUDE_DIR)
if(ADOLC_FOUND AND NOT TARGET ADOLC::ADOLC)
  add_library(ADOLC::ADOLC UNKNOWN IMPORTED)
  set_target_properties(ADOLC::ADOLC PROPERTIES IMPORTED_LOCATION "${ADOLC_LIBRARY}"
                                                INTERFACE_INCLUDE_DIRECTORIES "${ADOLC_INCLUDE_DIR}")
endif()
mark_as_advanced(ADOLC_INCLUDE_DIR ADOLC_LIBRARY)
