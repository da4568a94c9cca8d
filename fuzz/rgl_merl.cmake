# libFuzzer targets for the RGL and MERL readers, included by fuzz/CMakeLists.txt. They are
# registered through brdf_add_fuzzer so run_fuzzers.sh (the fuzz_readers test) runs them for a
# bounded time like every other reader. The hand-made broken files under
# tests/data/broken/{rgl,merl}/ are replayed by rgl_test and merl_test in every build.
brdf_add_fuzzer(rgl_fuzzer ${CMAKE_CURRENT_LIST_DIR}/rgl_fuzzer.cpp
                ${CMAKE_CURRENT_LIST_DIR}/corpus/rgl)
brdf_add_fuzzer(merl_fuzzer ${CMAKE_CURRENT_LIST_DIR}/merl_fuzzer.cpp
                ${CMAKE_CURRENT_LIST_DIR}/corpus/merl)
