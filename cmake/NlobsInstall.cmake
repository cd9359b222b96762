# `cmake --install` produces a CMake package: find_package(nlobs) gives nlobs::solvers,
# nlobs::models, nlobs::observers and nlobs::registry (and nlobs::common, which they share).
include(CMakePackageConfigHelpers)

install(TARGETS nlobs_common nlobs_solvers nlobs_models nlobs_observers nlobs_registry
        EXPORT nlobsTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(layer common solvers models observers registry)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${layer}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

set(NLOBS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/nlobs)
install(EXPORT nlobsTargets NAMESPACE nlobs:: DESTINATION ${NLOBS_CMAKE_DIR})
configure_package_config_file(cmake/nlobsConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfig.cmake
                              INSTALL_DESTINATION ${NLOBS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/nlobsConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfig.cmake ${PROJECT_SOURCE_DIR}/cmake/FindADOLC.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfigVersion.cmake
        DESTINATION ${NLOBS_CMAKE_DIR})
