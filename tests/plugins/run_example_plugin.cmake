# ctest driver (cmake -P): install nlobs into a scratch prefix, build examples/plugin against it
# as a user would (its own project, find_package(nlobs)), then load the plugin into the installed
# nlobs: a scenario with the plugin's model (the plugin's engine in a window among the built-in
# observers) and a suite row of the plugin's engine beside KINSOL. Fails on the first error.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${NLOBS_BUILD_DIR} --prefix ${prefix}
                OUTPUT_QUIET RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
set(flags "")
if(SANITIZE)  # nlobs' libraries are instrumented: link the runtimes too
  set(flags "-fsanitize=address,undefined")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${PLUGIN_SOURCE_DIR} -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
                        -DCMAKE_CXX_FLAGS=${flags}
                OUTPUT_QUIET RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring examples/plugin against ${prefix} failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build OUTPUT_QUIET RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building examples/plugin failed (${rc})")
endif()
set(nlobs ${prefix}/bin/nlobs)
set(plugin ${WORK_DIR}/build/libnlobs_example_plugin.so)

# The scenario: the windows (one with the plugin's engine) reconstruct the state; every
# observer, the plugin's two observer types included, gives a finite estimate.
execute_process(COMMAND ${nlobs} --plugin ${plugin} run ${PLUGIN_SOURCE_DIR}/fitzhugh_nagumo.json
                        --out ${WORK_DIR}/run
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "nlobs run with the plugin's model failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK_DIR}/run/summary.json summary)
string(JSON observers LENGTH "${summary}" observers)
if(NOT observers EQUAL 7)
  message(FATAL_ERROR "summary.json has ${observers} observers, the scenario 7:\n${summary}")
endif()
math(EXPR last "${observers} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${summary}" observers ${i} name)
  string(JSON mse GET "${summary}" observers ${i} mse_after_window 0)
  if(NOT mse LESS 1e300)  # null (non-finite) or not a number
    message(FATAL_ERROR "observer ${name}: MSE of x1 after the window is ${mse}")
  endif()
  if(name MATCHES "^window" AND NOT mse LESS 1e-6)
    message(FATAL_ERROR "observer ${name}: MSE of x1 after the window ${mse}, expected < 1e-6")
  endif()
  message(STATUS "${name}: MSE(x1) after the window ${mse}")
endforeach()

# The plugin's engine beside KINSOL on the plugin's problem set.
execute_process(COMMAND ${nlobs} --plugin ${plugin} suite example
                        --solvers bad-broyden,newton,kinsol:newton --json
                OUTPUT_VARIABLE rows ERROR_VARIABLE err RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "nlobs suite example failed (${rc}):\n${rows}\n${err}")
endif()
string(JSON count LENGTH "${rows}")
set(broyden_solved 0)
set(kinsol_rows 0)
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON solver GET "${rows}" ${i} solver)
  string(JSON solved GET "${rows}" ${i} solved)
  string(JSON problem GET "${rows}" ${i} problem)
  string(JSON start GET "${rows}" ${i} start)
  if(solver STREQUAL "bad-broyden" AND solved)
    math(EXPR broyden_solved "${broyden_solved} + 1")
  endif()
  if(solver STREQUAL "kinsol:newton")
    math(EXPR kinsol_rows "${kinsol_rows} + 1")
  endif()
  message(STATUS "${problem} ${start} ${solver}: solved ${solved}")
endforeach()
if(broyden_solved LESS 3 OR NOT kinsol_rows EQUAL 4)
  message(FATAL_ERROR "expected bad-broyden to solve at least 3 of the 4 (problem, start) pairs and "
                      "4 KINSOL rows; got ${broyden_solved} and ${kinsol_rows}:\n${rows}")
endif()
