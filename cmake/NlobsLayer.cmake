# nlobs_add_layer(<layer> [SOURCES ...] [DEPENDS ...]): the library of one layer, nlobs::<layer>,
# with public headers under <layer>/include/nlobs/<layer>/. Without sources it is header-only.
#
# Shared libraries: a plugin (nlobs_add_plugin) and the nlobs executable then see one engine
# registry, one model registry, ... — the ones in these libraries. The soname carries
# major.minor, so a plugin built against another minor version does not load.
# -fno-semantic-interposition lets the compiler inline and call directly inside a library, as
# in a static one (nlobs does not support interposing its own symbols).
function(nlobs_add_layer layer)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  set(target nlobs_${layer})
  set(include_dir $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(ARG_SOURCES)
    add_library(${target} SHARED ${ARG_SOURCES})
    nlobs_shared_library_properties(${target})
    target_include_directories(${target} PUBLIC ${include_dir})
    target_compile_features(${target} PUBLIC cxx_std_20)
    target_link_libraries(${target} PUBLIC ${ARG_DEPENDS})
    nlobs_target_warnings(${target})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${include_dir})
    target_compile_features(${target} INTERFACE cxx_std_20)
    target_link_libraries(${target} INTERFACE ${ARG_DEPENDS})
  endif()
  add_library(nlobs::${layer} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${layer})
endfunction()

# Version, soname and run path of one of nlobs' shared libraries (the layers, nlobs::reference).
function(nlobs_shared_library_properties target)
  set_target_properties(${target} PROPERTIES
    VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
    INSTALL_RPATH "$ORIGIN"  # the other nlobs libraries lie beside it
    INSTALL_RPATH_USE_LINK_PATH ON)  # and its dependencies where they were found (not /usr/lib)
  target_compile_options(${target} PRIVATE -fno-semantic-interposition)
endfunction()
