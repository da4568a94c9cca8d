# Modules loaded on first use (processing/include/brdf/core/lazy_module.h): code whose
# dependencies are too heavy to map into every `brdf` process (OpenImageIO, and any other
# library that pulls in dozens of shared objects) is built as a MODULE library and reached
# through brdf::LazyModule.
include(GNUInstallDirs)

# Where modules live: <build>/lib/brdf-toolchain in the build tree, and
# <prefix>/<libdir>/brdf-toolchain once installed. The loader finds the installed folder from
# the executable's own folder (<prefix>/<bindir>), so an installed tree can be moved.
set(BRDF_MODULE_SUBDIR "brdf-toolchain")
set(BRDF_BUILD_MODULE_DIR "${PROJECT_BINARY_DIR}/lib/${BRDF_MODULE_SUBDIR}")
set(BRDF_INSTALL_MODULE_DIR "${CMAKE_INSTALL_LIBDIR}/${BRDF_MODULE_SUBDIR}")
file(RELATIVE_PATH BRDF_MODULE_DIR_FROM_EXE
     "${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}"
     "${CMAKE_INSTALL_PREFIX}/${BRDF_INSTALL_MODULE_DIR}")

# brdf_add_lazy_module(NAME [NO_INSTALL] SOURCES src... LIBS lib...)
#   Builds lib<NAME>.so into the module folder, installs it (unless NO_INSTALL: test fixtures), hides every symbol except the
#   BRDF_MODULE_ENTRY functions and defines BRDF_VERSION_STRING for BRDF_DEFINE_MODULE_ABI().
#   Whatever the module links (LIBS) is mapped only when the module is loaded. A static
#   project library linked into a module must be built with POSITION_INDEPENDENT_CODE ON.
function(brdf_add_lazy_module name)
  cmake_parse_arguments(ARG "NO_INSTALL" "" "SOURCES;LIBS" ${ARGN})
  add_library(${name} MODULE ${ARG_SOURCES})
  set_target_properties(${name} PROPERTIES
    LIBRARY_OUTPUT_DIRECTORY "${BRDF_BUILD_MODULE_DIR}"
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_definitions(${name} PRIVATE BRDF_VERSION_STRING="${PROJECT_VERSION}")
  target_link_libraries(${name} PRIVATE brdf::warnings ${ARG_LIBS})
  # A module must not depend on symbols of the program that loads it.
  target_link_options(${name} PRIVATE "LINKER:--no-undefined")
  if(NOT ARG_NO_INSTALL)
    install(TARGETS ${name} LIBRARY DESTINATION "${BRDF_INSTALL_MODULE_DIR}")
  endif()
endfunction()
