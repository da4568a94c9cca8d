# brdf::processing: resampling to the LUT grid (docs/design.md §5), grazing extrapolation (docs/design.md §6)
# and a measurement evaluated through its LUT (measurement_brdf.h). Fitting (Ceres) joins this target later.
add_library(brdf_processing
  ${CMAKE_CURRENT_LIST_DIR}/extrapolation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/slice_interpolator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/resample.cpp
  ${CMAKE_CURRENT_LIST_DIR}/measurement_brdf.cpp
)
add_library(brdf::processing ALIAS brdf_processing)
# Position-independent like brdf_core: the fitter's lazy module links it.
set_target_properties(brdf_processing PROPERTIES POSITION_INDEPENDENT_CODE ON)
target_include_directories(brdf_processing PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                           PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(brdf_processing
  PUBLIC brdf::core
  PRIVATE brdf::warnings TBB::tbb nlohmann_json::nlohmann_json)
