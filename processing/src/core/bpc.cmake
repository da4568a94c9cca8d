# .bpc reader and writer: target_sources(brdf_core PRIVATE ...) added by that part.
target_sources(brdf_core PRIVATE src/core/bpc.cpp)
