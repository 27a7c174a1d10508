# EOL_FUZZ=ON: a build tree of the libFuzzer targets (tests/fuzz/) and the libraries they need,
# nothing else. Everything is compiled with -fsanitize=fuzzer-no-link,address,undefined (the
# coverage libFuzzer steers by, and the sanitizers that turn a silent bug into a finding);
# the fuzzers link with -fsanitize=fuzzer,address,undefined. Undefined behaviour aborts
# (no recovery), so libFuzzer keeps the input. Build the target eol_fuzzers; see
# tests/README.md "Fuzzing" and tests/fuzz/run_fuzzers.sh.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "EOL_FUZZ=ON needs clang (libFuzzer): configure with "
                      "-DCMAKE_CXX_COMPILER=clang++-14 (Debian packages clang-14 and "
                      "libclang-rt-14-dev); this compiler is ${CMAKE_CXX_COMPILER_ID}")
endif()
set(EOL_SANITIZERS address,undefined)
add_compile_options(-fsanitize=fuzzer-no-link,${EOL_SANITIZERS} -fno-sanitize-recover=all
                    -fno-omit-frame-pointer)
set(EOL_FUZZ_LINK_FLAGS -fsanitize=fuzzer,${EOL_SANITIZERS})
add_subdirectory(analysis)
# Of eol::analysis the fuzzers link only these sources (the linker's closure over the
# readers, 15 of 53 files); the rest is Eigen-heavy numerics that took most of a cold build.
# A reader that comes to need another file fails to link naming the symbol: add it here.
set(A ${PROJECT_SOURCE_DIR}/analysis)
set_property(TARGET eol_analysis PROPERTY SOURCES
  ${A}/frf.cc ${A}/qc/curve_mask.cc ${A}/signal/fft.cc ${A}/signal/waveform.cc
  ${A}/signal/multisine.cc ${A}/fit/motional_jacobian.cc ${A}/fit/least_squares.cc
  ${A}/fit/resonance_fit.cc ${A}/signal/frf_method.cc ${A}/qc/bond_index.cc
  ${A}/qc/f0_pressure.cc ${A}/signal/excitation_design.cc ${A}/qc/line_measurement.cc ${A}/fit/cramer_rao.cc
  ${A}/model/motor_model.cc ${A}/qc/measurement.cc)
add_subdirectory(drivers)
add_subdirectory(tests/fuzz)
