# The Debian package (`cpack -G DEB` in the build folder, docs/packaging.md):
# brdf-toolchain_<version>_<arch>.deb with everything `cmake --install` installs under /usr
# (tools, modules, material library, udev rule, Python module) plus what Debian policy asks of
# a package: man pages, bash completions, copyright and changelog. The man pages and the
# completions are generated from the built tools' --help texts (tools/packaging/cli_docs.py),
# so they say what the programs say. Included from the top-level CMakeLists.txt after tools/.
include(GNUInstallDirs)
# Debian's Python runs the generator (also in a build without tests, where
# cmake/Dependencies.cmake does not look for it).
find_program(BRDF_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH REQUIRED)

set(BRDF_PACKAGING_SOURCE_DIR "${PROJECT_SOURCE_DIR}/tools/packaging")
set(BRDF_PACKAGING_BINARY_DIR "${PROJECT_BINARY_DIR}/packaging")
set(BRDF_PACKAGE_MAINTAINER
    "brdf-toolchain maintainers <maintainers@users.noreply.h-seed-ebf1d216.example>"
    CACHE STRING "Maintainer field of the Debian package")

# Man pages, completions and the compressed changelog, remade whenever a tool is relinked.
set(BRDF_CLI_DOCS_ARGS --brdf "$<TARGET_FILE:brdf>")
set(BRDF_CLI_DOCS_OUTPUTS
    "${BRDF_PACKAGING_BINARY_DIR}/man/brdf.1.gz" "${BRDF_PACKAGING_BINARY_DIR}/completions/brdf")
set(BRDF_CLI_DOCS_PROGRAMS brdf)
if(TARGET brdf-view)
  list(APPEND BRDF_CLI_DOCS_ARGS --brdf-view "$<TARGET_FILE:brdf-view>")
  list(APPEND BRDF_CLI_DOCS_OUTPUTS "${BRDF_PACKAGING_BINARY_DIR}/man/brdf-view.1.gz"
       "${BRDF_PACKAGING_BINARY_DIR}/completions/brdf-view")
  list(APPEND BRDF_CLI_DOCS_PROGRAMS brdf-view)
endif()
add_custom_command(
  OUTPUT ${BRDF_CLI_DOCS_OUTPUTS} "${BRDF_PACKAGING_BINARY_DIR}/changelog.gz"
  COMMAND ${BRDF_PYTHON3} "${BRDF_PACKAGING_SOURCE_DIR}/cli_docs.py" ${BRDF_CLI_DOCS_ARGS}
          --version ${PROJECT_VERSION} --changelog "${BRDF_PACKAGING_SOURCE_DIR}/changelog"
          --out "${BRDF_PACKAGING_BINARY_DIR}"
  DEPENDS ${BRDF_CLI_DOCS_PROGRAMS} "${BRDF_PACKAGING_SOURCE_DIR}/cli_docs.py"
          "${BRDF_PACKAGING_SOURCE_DIR}/changelog"
  COMMENT "Man pages and bash completions from the tools' --help"
  VERBATIM)
add_custom_target(brdf_cli_docs ALL DEPENDS ${BRDF_CLI_DOCS_OUTPUTS})

foreach(program IN LISTS BRDF_CLI_DOCS_PROGRAMS)
  install(FILES "${BRDF_PACKAGING_BINARY_DIR}/man/${program}.1.gz"
          DESTINATION "${CMAKE_INSTALL_MANDIR}/man1")
  install(FILES "${BRDF_PACKAGING_BINARY_DIR}/completions/${program}"
          DESTINATION "${CMAKE_INSTALL_DATADIR}/bash-completion/completions")
endforeach()
install(FILES "${BRDF_PACKAGING_SOURCE_DIR}/copyright" "${BRDF_PACKAGING_BINARY_DIR}/changelog.gz"
        DESTINATION "${CMAKE_INSTALL_DOCDIR}")

# The Python module is built for one interpreter (python/CMakeLists.txt): the package depends
# on that Python version and on numpy, which the module imports (not a shared library, so
# dpkg-shlibdeps cannot see them).
set(BRDF_PACKAGE_EXTRA_DEPENDS "")
if(BRDF_BUILD_PYTHON)
  execute_process(COMMAND ${BRDF_PYTHON3} -c "import sys; print('%d.%d' % sys.version_info[:2])"
                  OUTPUT_VARIABLE BRDF_PACKAGE_PYTHON_VERSION OUTPUT_STRIP_TRAILING_WHITESPACE
                  COMMAND_ERROR_IS_FATAL ANY)
  string(REGEX REPLACE "^([0-9]+)\\.([0-9]+)$" "\\1.\\2" _major_minor "${BRDF_PACKAGE_PYTHON_VERSION}")
  math(EXPR _next_minor "${CMAKE_MATCH_2} + 1")
  set(BRDF_PACKAGE_EXTRA_DEPENDS
      "python3 (>= ${_major_minor}~), python3 (<< ${CMAKE_MATCH_1}.${_next_minor}), python3-numpy")
endif()

set(CPACK_GENERATOR "DEB")  # plain `cpack` makes the Debian package too
set(CPACK_PACKAGE_NAME "brdf-toolchain")
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGE_CONTACT "${BRDF_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "measured reflectance (BRDF) to engine-ready lookup textures")
# The extended description, one line per control-file line (lintian wants them under 80).
string(JOIN "\n" CPACK_PACKAGE_DESCRIPTION
  "brdf-toolchain drives a portable contact scatterometer (USB, HID or a"
  "simulator), stores captures crash-safely, extrapolates the unmeasured grazing"
  "angles, fits analytic BRDF models and exports RGB9E5 lookup textures (KTX2,"
  "DDS, EXR), atlases and engine kits for Unity, Unreal, Godot and three.js."
  ""
  "This package holds the command-line tool brdf, the viewer brdf-view, the"
  "virtual sample material library, the udev rule that gives users access to"
  "the instrument, and the Python module brdf for numpy.")
set(CPACK_DEBIAN_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_PACKAGE_PRIORITY "optional")
set(CPACK_DEBIAN_FILE_NAME "DEB-DEFAULT")  # brdf-toolchain_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)      # Depends from the ELF files (dpkg-shlibdeps)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${BRDF_PACKAGE_EXTRA_DEPENDS}")
# brdf-view --screenshot runs itself under xvfb-run when there is no display.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "xvfb, xauth")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS
    OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
# Debian ships binaries without their debugging sections (lintian: unstripped-binary-or-object).
set(CPACK_STRIP_FILES ON)
set(CPACK_THREADS 2)
include(CPack)
