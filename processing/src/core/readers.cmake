# Importers of third-party formats: target_sources(brdf_core PRIVATE ...) added by that part.
target_sources(brdf_core PRIVATE
  src/core/readers/rgl_tensor.cpp
  src/core/readers/rgl_brdf.cpp
)
target_sources(brdf_core PRIVATE
  src/core/readers/merl.cpp
  src/core/sha256.cpp
)
