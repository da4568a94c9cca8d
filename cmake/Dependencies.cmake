# Every dependency is a Debian 12 package installed by tools/install-deps.sh.
find_package(Threads REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(fmt REQUIRED)
find_package(CLI11 REQUIRED)
find_package(TBB REQUIRED)
find_package(Eigen3 REQUIRED NO_MODULE)
# brdf::fit (and the tests of its private kernels).
find_package(Ceres REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBUSB REQUIRED IMPORTED_TARGET libusb-1.0)
pkg_check_modules(HIDAPI REQUIRED IMPORTED_TARGET hidapi-libusb)

# brdf::image_io writes and reads EXR and PNG itself; OpenImageIO is only linked by the module
# that reads every other format (cmake/LazyModule.cmake).
find_package(OpenEXR 3 REQUIRED)
find_package(PNG REQUIRED)
find_package(OpenImageIO REQUIRED)
# OpenImageIO 2.4's config names /usr/include/opencv4, which Debian does not ship (docs/design.md §3).
foreach(oiio_target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${oiio_target})
    get_target_property(oiio_includes ${oiio_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(oiio_includes)
      list(FILTER oiio_includes EXCLUDE REGEX "opencv4")
      set_target_properties(${oiio_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${oiio_includes}")
    endif()
  endif()
endforeach()

if(BRDF_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
  # zlib's crc32: the independent oracle of brdf::Crc32 and of the exported payload checksums.
  find_package(ZLIB REQUIRED)
  find_program(BRDF_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH REQUIRED)
  find_program(BRDF_XVFB_RUN xvfb-run)
  find_program(BRDF_NODE node)
endif()
if(BRDF_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# The viewer (brdf::viewer, tools/brdf-view): VTK 9.1 and Xlib (to check for a display).
if(BRDF_BUILD_VIEWER)
  find_package(VTK 9.1 REQUIRED COMPONENTS
    CommonCore CommonDataModel CommonTransforms FiltersCore FiltersGeneral FiltersSources
    ImagingCore IOImage InteractionStyle InteractionWidgets RenderingAnnotation RenderingCore
    RenderingFreeType RenderingOpenGL2)
  find_package(X11 REQUIRED)
endif()
