# `cmake --install` produces a CMake package: find_package(nlobs) gives nlobs::solvers,
# nlobs::models, nlobs::observers, nlobs::registry and nlobs::runs (and nlobs::common, which they share), the
# nlobs_add_plugin() function, and with COMPONENTS reference the reference solvers
# (nlobs::reference: KINSOL, MINPACK, GSL and the suite runner).
include(CMakePackageConfigHelpers)

install(TARGETS nlobs_common nlobs_solvers nlobs_models nlobs_observers nlobs_registry nlobs_runs
        EXPORT nlobsTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(layer common solvers models observers registry runs)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${layer}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

set(NLOBS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/nlobs)
install(EXPORT nlobsTargets NAMESPACE nlobs:: DESTINATION ${NLOBS_CMAKE_DIR})

# The optional component: its own export set, read only when asked for.
if(TARGET nlobs_reference)
  install(TARGETS nlobs_reference EXPORT nlobsReferenceTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/reference/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT nlobsReferenceTargets NAMESPACE nlobs:: DESTINATION ${NLOBS_CMAKE_DIR})
endif()

configure_package_config_file(cmake/nlobsConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfig.cmake
                              INSTALL_DESTINATION ${NLOBS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/nlobsConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfig.cmake ${PROJECT_SOURCE_DIR}/cmake/FindADOLC.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindKLU.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindUMFPACK.cmake
              ${PROJECT_SOURCE_DIR}/cmake/NlobsPlugin.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/nlobsConfigVersion.cmake
        DESTINATION ${NLOBS_CMAKE_DIR})
