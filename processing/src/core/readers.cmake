# Importers of third-party formats: target_sources(brdf_core PRIVATE ...) added by that part.
