# Further command sources: target_sources(brdf PRIVATE ...) and their libraries.
