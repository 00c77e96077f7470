# Compile options shared by every mufric target, per language.
add_library(mufric_options INTERFACE)
target_compile_options(mufric_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion -Wnon-virtual-dtor
  -Wold-style-cast -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2>
  $<$<COMPILE_LANGUAGE:C>:-Wall -Wextra -Wpedantic>
  $<$<COMPILE_LANGUAGE:Fortran>:-Wall>)
if(MUFRIC_NATIVE)
  # GCC 12 reports false -Wmaybe-uninitialized inside its own AVX-512 intrinsics when Eigen
  # inlines them (GCC bug 105593); silenced for native builds only.
  target_compile_options(mufric_options INTERFACE -march=native $<$<COMPILE_LANGUAGE:CXX>:-Wno-maybe-uninitialized>)
endif()
if(MUFRIC_FUZZ)
  # ASan + UBSan in every library; libFuzzer's coverage only in the code that parses the fuzz
  # targets' input (mufric_fuzz_coverage below; the targets add -fsanitize=fuzzer, libFuzzer's main).
  # Coverage costs every instrumented function 2-2.5x at run time (the micro-solver's tests: 57.0
  # against 22.7 s), and the test command's one clang build also runs the sanitizer tests.
  target_compile_options(mufric_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(mufric_options INTERFACE -fsanitize=address,undefined)
endif()
# libFuzzer coverage for a target's own code, or for some of its sources (MUFRIC_FUZZ builds only):
#   mufric_fuzz_coverage(TARGETS mufric_common)   mufric_fuzz_coverage(SOURCES model_file.cpp)
# SOURCES are set in the calling directory (a source property); they leave the unity build.
function(mufric_fuzz_coverage)
  if(NOT MUFRIC_FUZZ)
    return()
  endif()
  cmake_parse_arguments(arg "" "" "TARGETS;SOURCES" ${ARGN})
  foreach(target IN LISTS arg_TARGETS)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endforeach()
  if(arg_SOURCES)
    set_property(SOURCE ${arg_SOURCES} DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} APPEND PROPERTY COMPILE_OPTIONS -fsanitize=fuzzer-no-link)
  endif()
endfunction()
if(MUFRIC_SANITIZE)
  target_compile_options(mufric_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(mufric_options INTERFACE -fsanitize=address,undefined)
endif()
if(MUFRIC_TSAN)
  target_compile_options(mufric_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(mufric_options INTERFACE -fsanitize=thread)
endif()
