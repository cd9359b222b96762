# nlobs_add_plugin(<name> <source>...): a plugin, lib<name>.so, that `nlobs --plugin` and
# NLOBS_PLUGIN_PATH load (nlobs/registry/plugin.hpp; docs/extending.md). A MODULE library: it is
# loaded, never linked against. It links nlobs' shared libraries, so its entries land in the
# registries of the program that loads it; add your own dependencies with
# target_link_libraries(<name> PRIVATE ...).
function(nlobs_add_plugin name)
  if(NOT ARGN)
    message(FATAL_ERROR "nlobs_add_plugin(${name}): give the plugin's source files")
  endif()
  add_library(${name} MODULE ${ARGN})
  target_link_libraries(${name} PRIVATE nlobs::registry)
  target_compile_features(${name} PRIVATE cxx_std_20)
  set_target_properties(${name} PROPERTIES PREFIX "lib" SUFFIX ".so")
endfunction()
