# Further command sources: target_sources(brdf PRIVATE ...) and their libraries.
target_sources(brdf PRIVATE brdf/cmd_import.cpp brdf/cmd_export_csv.cpp)
target_sources(brdf PRIVATE brdf/cmd_info.cpp)
target_sources(brdf PRIVATE brdf/cmd_capture.cpp brdf/cmd_devices.cpp)
target_link_libraries(brdf PRIVATE brdf::device brdf::device_emulation)
target_sources(brdf PRIVATE
  brdf/cmd_convert.cpp
  brdf/cmd_atlas.cpp
  brdf/batch.cpp
  brdf/cmd_repair.cpp
)
target_link_libraries(brdf PRIVATE brdf::processing brdf::exporter TBB::tbb Threads::Threads)
# The input rules (what a file is, damaged captures, opening any source): brdf::sources.
target_link_libraries(brdf PRIVATE brdf::sources)
# brdf fit (Ceres through brdf::fit only)
target_sources(brdf PRIVATE brdf/cmd_fit.cpp)
target_link_libraries(brdf PRIVATE brdf::fit)
target_link_libraries(brdf PRIVATE brdf::engines)  # --engine (convert, atlas)
