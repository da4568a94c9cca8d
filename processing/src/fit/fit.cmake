# brdf::fit — fitting analytic models with Ceres (brdf/processing/fit.h). Its own target so that
# only what fits links Ceres; the public header holds std types only.
find_package(Ceres REQUIRED)
add_library(brdf_fit
  ${CMAKE_CURRENT_LIST_DIR}/fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fit_data.cpp
  ${CMAKE_CURRENT_LIST_DIR}/auto_extrapolation.cpp
)
add_library(brdf::fit ALIAS brdf_fit)
target_include_directories(brdf_fit PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                    PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(brdf_fit
  PUBLIC brdf::processing brdf::core
  PRIVATE brdf::warnings Ceres::ceres nlohmann_json::nlohmann_json)
# The residual functors are Jet arithmetic that only pays off fully inlined: -O3 here.
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/fit.cpp PROPERTIES COMPILE_OPTIONS "-O3")
