# Sanitizers and fuzzers: build options for a separate build directory (scripts/run_tests.sh uses
# build-sanitize/ with clang; docs/reference/testing.md).
#
# BODYFIT_SANITIZE=address,undefined instruments every target of the project. UBSan halts at the
# first error (-fno-sanitize-recover=all), so a test sees it as a failure; the stack traces need
# frame pointers and line tables. The system libraries (OpenMesh, TBB, GDAL...) are not
# instrumented: errors inside them are not seen, calls into them are.
#
# BODYFIT_BUILD_FUZZERS builds the libFuzzer targets of tests/fuzz (clang only). Only the sources
# of the core that read files get the coverage instrumentation libFuzzer steers by; the rest of the
# core, and the test suite built beside them, run at the sanitizers' speed alone.
set(BODYFIT_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined (empty: none)")
option(BODYFIT_BUILD_FUZZERS "Build the libFuzzer targets of tests/fuzz (clang; with BODYFIT_SANITIZE)" OFF)

if(BODYFIT_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    message(FATAL_ERROR "BODYFIT_SANITIZE needs gcc or clang")
  endif()
  add_compile_options(-fsanitize=${BODYFIT_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${BODYFIT_SANITIZE})
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    add_compile_options(-gline-tables-only)
  else()
    add_compile_options(-g1)
  endif()
  message(STATUS "bodyfit: sanitizers ${BODYFIT_SANITIZE}")
endif()

if(BODYFIT_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "BODYFIT_BUILD_FUZZERS needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++")
  endif()
  if(NOT BODYFIT_SANITIZE)
    message(FATAL_ERROR "BODYFIT_BUILD_FUZZERS needs BODYFIT_SANITIZE (e.g. address,undefined)")
  endif()
endif()
