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
# ASan + UBSan in every library for MUFRIC_FUZZ and MUFRIC_SANITIZE; libFuzzer's coverage only in
# the code that parses the fuzz targets' input (mufric_fuzz_coverage below; the targets add
# -fsanitize=fuzzer, libFuzzer's main). Coverage costs every instrumented function 2-2.5x at run
# time (the micro-solver's tests: 57.0 against 22.7 s), and the test command's one clang build also
# runs the sanitizer tests. Four of UBSan's checks are left out where no
# untrusted input is parsed: object-size and null check what ASan checks already (an access outside
# an object; a null dereference is a SEGV that ASan reports with its stack), pointer-overflow forms
# a pointer whose dereference ASan checks, and x86-64 loads misaligned data (alignment). Their
# checks in every Eigen expression stopped clang inlining Eigen's kernels: one draw of the tiny CLI
# test scene took 18.1 s with them, 2.7 s without, 1.0 s in Release
# (bench/studies/test_time/README.md, "The
# test command's time"). The code the fuzz targets feed keeps all of UBSan (mufric_fuzz_coverage).
set(mufric_ubsan_parser_only_checks alignment,null,pointer-overflow,object-size)
if(MUFRIC_FUZZ OR MUFRIC_SANITIZE)
  target_compile_options(mufric_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined -fno-sanitize=${mufric_ubsan_parser_only_checks})
  target_link_options(mufric_options INTERFACE -fsanitize=address,undefined)
endif()
# libFuzzer coverage and all of UBSan for a target's own code, or for some of its sources (MUFRIC_FUZZ
# builds only):
#   mufric_fuzz_coverage(TARGETS mufric_common)   mufric_fuzz_coverage(SOURCES model_file.cpp)
# Called in the directory of the target or sources; the sources leave the unity build.
function(mufric_fuzz_coverage)
  if(NOT MUFRIC_FUZZ)
    return()
  endif()
  cmake_parse_arguments(arg "" "" "TARGETS;SOURCES" ${ARGN})
  # Source properties, not target options: a target's own options come before those of mufric_options,
  # whose -fno-sanitize would win.
  set(sources ${arg_SOURCES})
  foreach(target IN LISTS arg_TARGETS)
    get_target_property(target_sources ${target} SOURCES)
    list(FILTER target_sources INCLUDE REGEX "\\.cpp$")
    list(APPEND sources ${target_sources})
  endforeach()
  set_property(SOURCE ${sources} DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} APPEND PROPERTY COMPILE_OPTIONS
               -fsanitize=fuzzer-no-link -fsanitize=${mufric_ubsan_parser_only_checks})
endfunction()
if(MUFRIC_TSAN)
  target_compile_options(mufric_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(mufric_options INTERFACE -fsanitize=thread)
endif()
