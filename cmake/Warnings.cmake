# All project targets link brdf_warnings; warnings live in this one place.
add_library(brdf_warnings INTERFACE)
add_library(brdf::warnings ALIAS brdf_warnings)
target_compile_options(brdf_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
    -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough>)
