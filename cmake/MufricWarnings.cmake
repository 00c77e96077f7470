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
  # Coverage for libFuzzer in every library; the targets add -fsanitize=fuzzer (libFuzzer's main).
  target_compile_options(mufric_options INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined -g)
  target_link_options(mufric_options INTERFACE -fsanitize=address,undefined)
endif()
if(MUFRIC_SANITIZE)
  target_compile_options(mufric_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(mufric_options INTERFACE -fsanitize=address,undefined)
endif()
if(MUFRIC_TSAN)
  target_compile_options(mufric_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer -g)
  target_link_options(mufric_options INTERFACE -fsanitize=thread)
endif()
