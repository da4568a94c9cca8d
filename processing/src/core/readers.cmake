# Importers of third-party formats: target_sources(brdf_core PRIVATE ...) added by that part.
target_sources(brdf_core PRIVATE
  src/core/readers/text_util.cpp
  src/core/readers/zemax.cpp
  src/core/readers/lighttools.cpp
  src/core/readers/csv.cpp
  src/core/readers/gonio.cpp
  src/core/readers/importers.cpp
  src/core/readers/rgl_tensor.cpp
  src/core/readers/rgl_brdf.cpp
)
target_sources(brdf_core PRIVATE
  src/core/readers/merl.cpp
  src/core/sha256.cpp
)
