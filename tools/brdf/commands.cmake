# Further command sources: target_sources(brdf PRIVATE ...) and their libraries.
target_sources(brdf PRIVATE brdf/cmd_info.cpp)
