# Further command sources: target_sources(brdf PRIVATE ...) and their libraries.
target_sources(brdf PRIVATE brdf/cmd_import.cpp brdf/cmd_export_csv.cpp)
target_sources(brdf PRIVATE brdf/cmd_info.cpp)
target_sources(brdf PRIVATE brdf/cmd_capture.cpp)
target_link_libraries(brdf PRIVATE brdf::device)
target_sources(brdf PRIVATE
  brdf/cmd_convert.cpp
  brdf/cmd_atlas.cpp
  brdf/batch.cpp
  brdf/sources.cpp
)
target_link_libraries(brdf PRIVATE brdf::processing brdf::exporter TBB::tbb Threads::Threads)
target_link_libraries(brdf PRIVATE brdf::engines)  # --engine (convert, atlas)
