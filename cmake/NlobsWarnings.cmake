# Warning and sanitizer flags for nlobs' own targets (never forced on consumers).
function(nlobs_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion)
  if(NLOBS_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# -O1 as the sanitizers' documentation recommends: the same checks (Eigen's assertions stay on:
# no NDEBUG), and Eigen-heavy tests run several times faster than at -O0.
if(NLOBS_SANITIZE)
  add_compile_options(-O1 -fsanitize=address,undefined -fno-omit-frame-pointer
                      -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
