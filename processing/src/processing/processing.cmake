# brdf_processing target: defined here once resampling lands.
