# brdf::sources: the input rules shared by the `brdf` tool, the viewer, the fitter and the
# previewer: what a file is (detect.h), the damaged-capture rule and repair (capture.h),
# opening any evaluable source and any LUT input (open.h).
add_library(brdf_sources
  ${CMAKE_CURRENT_LIST_DIR}/detect.cpp
  ${CMAKE_CURRENT_LIST_DIR}/capture.cpp
  ${CMAKE_CURRENT_LIST_DIR}/open.cpp
)
add_library(brdf::sources ALIAS brdf_sources)
target_include_directories(brdf_sources PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                        PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(brdf_sources
  PUBLIC brdf::core brdf::processing brdf::exporter
  PRIVATE brdf::warnings nlohmann_json::nlohmann_json)
