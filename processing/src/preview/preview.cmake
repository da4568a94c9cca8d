# brdf::preview: environment-lit previews of any BrdfSource (preview.h). No VTK; images are
# read and written through brdf::image_io (OpenImageIO only in its lazily loaded module).
add_library(brdf_preview
  ${CMAKE_CURRENT_LIST_DIR}/environment_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/samplers.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/renderer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hierarchical.cpp
  ${CMAKE_CURRENT_LIST_DIR}/image.cpp
)
add_library(brdf::preview ALIAS brdf_preview)
target_include_directories(brdf_preview PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                        PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(brdf_preview
  PUBLIC brdf::core
  PRIVATE brdf::warnings brdf::image_io Threads::Threads)
