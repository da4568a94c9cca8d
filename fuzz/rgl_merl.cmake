# libFuzzer targets for the RGL and MERL readers. Include this file from fuzz/CMakeLists.txt
# (built when BRDF_BUILD_FUZZERS is ON; needs clang: configure the fuzzing build with
# -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang -DBRDF_BUILD_FUZZERS=ON).
#
# Each target compiles the reader sources it exercises itself, so they are instrumented with
# -fsanitize=fuzzer,address whatever flags brdf_core was built with (coverage feedback needs
# the reader code instrumented, and an ASan-built brdf_core would break the normal tests).
set(BRDF_FUZZ_CORE_DIR ${PROJECT_SOURCE_DIR}/processing/src/core)
set(brdf_rgl_fuzzer_sources
  ${CMAKE_CURRENT_LIST_DIR}/rgl_fuzzer.cpp
  ${BRDF_FUZZ_CORE_DIR}/error.cpp
  ${BRDF_FUZZ_CORE_DIR}/file_util.cpp
  ${BRDF_FUZZ_CORE_DIR}/readers/rgl_tensor.cpp
  ${BRDF_FUZZ_CORE_DIR}/readers/rgl_brdf.cpp)
set(brdf_merl_fuzzer_sources
  ${CMAKE_CURRENT_LIST_DIR}/merl_fuzzer.cpp
  ${BRDF_FUZZ_CORE_DIR}/error.cpp
  ${BRDF_FUZZ_CORE_DIR}/file_util.cpp
  ${BRDF_FUZZ_CORE_DIR}/sha256.cpp
  ${BRDF_FUZZ_CORE_DIR}/readers/merl.cpp)

foreach(reader rgl merl)
  set(target brdf_${reader}_fuzzer)
  add_executable(${target} ${brdf_${reader}_fuzzer_sources})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/processing/include
                                               ${BRDF_FUZZ_CORE_DIR})
  target_compile_options(${target} PRIVATE -fsanitize=fuzzer,address -fno-omit-frame-pointer)
  target_link_options(${target} PRIVATE -fsanitize=fuzzer,address)
  target_link_libraries(${target} PRIVATE brdf::warnings)

  if(BRDF_BUILD_TESTS)
    # Replay: the seeds, the hand-made broken files and any kept crash inputs must all pass.
    set(inputs ${CMAKE_CURRENT_LIST_DIR}/corpus/${reader}
               ${PROJECT_SOURCE_DIR}/tests/data/broken/${reader})
    add_test(NAME ${target}_replay COMMAND ${target} -runs=0 ${inputs})
    # A bounded run (CI): new inputs go to a scratch corpus in the build tree, crash inputs
    # next to it; keep any crash file as a regression input under fuzz/corpus/${reader}/.
    set(work ${CMAKE_CURRENT_BINARY_DIR}/${target}_corpus)
    file(MAKE_DIRECTORY ${work})
    add_test(NAME ${target}_bounded
             COMMAND ${target} -max_total_time=60 -max_len=4096 -timeout=10 -rss_limit_mb=2048
                     -artifact_prefix=${CMAKE_CURRENT_BINARY_DIR}/${target}- ${work} ${inputs})
    set_tests_properties(${target}_replay ${target}_bounded PROPERTIES LABELS fuzz)
    set_tests_properties(${target}_bounded PROPERTIES TIMEOUT 300)
  endif()
endforeach()
