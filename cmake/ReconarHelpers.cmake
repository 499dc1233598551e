# Helper functions shared by every module: one target per module, explicit PUBLIC/PRIVATE links.

set(RECONAR_WARNING_FLAGS -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wno-missing-field-initializers)
if(RECONAR_WERROR)
  list(APPEND RECONAR_WARNING_FLAGS -Werror)
endif()

if(RECONAR_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# Architecture flags for SIMD kernels: each instruction set lives in its own translation unit.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(RECONAR_ARCH_X86 ON)
  set(RECONAR_AVX2_FLAGS -mavx2 -mfma)
  set(RECONAR_AVX512_FLAGS -mavx512f -mfma)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64|ARM64)$")
  set(RECONAR_ARCH_ARM64 ON)
endif()

# reconar_add_kernel_sources(TARGET [SSE2 sources...] [AVX2 sources...] [AVX512 sources...] [NEON sources...])
# Adds a module's SIMD kernels: each instruction set's sources only where the target architecture
# has it, compiled with its flags (RECONAR_<ISA>_FLAGS; those sources skip the libraries'
# precompiled header, built without them), and defines RECONAR_HAVE_<ISA>_KERNELS for the target,
# the one macro the dispatchers test (core/base/kernel_choice.h).
function(reconar_add_kernel_sources target)
  cmake_parse_arguments(ARG "" "" "SSE2;AVX2;AVX512;NEON" ${ARGN})
  set(isas)
  if(RECONAR_ARCH_X86)
    set(isas SSE2 AVX2 AVX512)
  elseif(RECONAR_ARCH_ARM64)
    set(isas NEON)
  endif()
  foreach(isa IN LISTS isas)
    if(NOT ARG_${isa})
      continue()
    endif()
    target_sources(${target} PRIVATE ${ARG_${isa}})
    if(RECONAR_${isa}_FLAGS)
      set_source_files_properties(${ARG_${isa}} PROPERTIES COMPILE_OPTIONS "${RECONAR_${isa}_FLAGS}"
                                  SKIP_PRECOMPILE_HEADERS ON)
    endif()
    target_compile_definitions(${target} PRIVATE RECONAR_HAVE_${isa}_KERNELS)
  endforeach()
endfunction()

# reconar_add_library(NAME SOURCES ... [PUBLIC_LINKS ...] [PRIVATE_LINKS ...])
# Creates target reconar_<NAME> with the repository root as include root ("core/base/status.h").
function(reconar_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LINKS;PRIVATE_LINKS" ${ARGN})
  add_library(reconar_${name} STATIC ${ARG_SOURCES})
  reconar_library_compile_settings(reconar_${name})
  target_link_libraries(reconar_${name} PUBLIC ${ARG_PUBLIC_LINKS} PRIVATE ${ARG_PRIVATE_LINKS})
  if(TARGET reconar_library_pch_host)
    target_precompile_headers(reconar_${name} REUSE_FROM reconar_library_pch_host)
  endif()
endfunction()

# The compile settings every library shares; the libraries' precompiled header is built with them.
function(reconar_library_compile_settings name)
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_compile_options(${name} PRIVATE ${RECONAR_WARNING_FLAGS})
endfunction()

# reconar_add_library_pch(): one precompiled header that every library reuses: Eigen and the
# standard headers most sources include (under clang it halved the libraries' compile time: 751 to
# 401 s of jobs in a cold build). A source compiled for other instructions than
# the header (the AVX2 and AVX-512 kernels) sets SKIP_PRECOMPILE_HEADERS; a mismatch is an error
# (clang; GCC under RECONAR_WERROR), never a silent miscompile.
function(reconar_add_library_pch)
  add_library(reconar_library_pch_host STATIC "${PROJECT_SOURCE_DIR}/cmake/library_pch_host.cc")
  reconar_library_compile_settings(reconar_library_pch_host)
  target_link_libraries(reconar_library_pch_host PRIVATE Eigen3::Eigen)
  target_precompile_headers(reconar_library_pch_host PRIVATE
      <Eigen/Dense>
      <algorithm> <array> <atomic> <cmath> <cstdint> <cstdio> <cstring> <functional> <limits> <map>
      <memory> <mutex> <optional> <set> <string> <thread> <utility> <vector>)
endfunction()

# The compile settings every test executable shares; the precompiled header is built with them,
# so a test can reuse it only while they are the same.
function(reconar_test_compile_settings name)
  target_compile_options(${name} PRIVATE ${RECONAR_WARNING_FLAGS})
  target_compile_definitions(${name} PRIVATE
      RECONAR_SHARED_DATA_DIR="${RECONAR_SHARED_DATA_DIR}"
      RECONAR_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(${name} PRIVATE GTest::gtest GTest::gtest_main)
endfunction()

# reconar_add_test_pch(): one precompiled header that every test reuses: GoogleTest, Eigen and the
# standard headers most tests include. Parsing them is about 2 s of a test source's 6 to 10 s
# compile; precompiled, it is done once per build. A test compiled with other definitions of the
# macros these headers read (EIGEN_RUNTIME_NO_MALLOC, NDEBUG) passes NO_PCH; a header that does not
# match is refused (clang: an error; GCC: -Winvalid-pch, an error under RECONAR_WERROR).
function(reconar_add_test_pch)
  add_executable(reconar_test_pch_host "${PROJECT_SOURCE_DIR}/tests/support/pch_host.cc")
  reconar_test_compile_settings(reconar_test_pch_host)
  target_link_libraries(reconar_test_pch_host PRIVATE Eigen3::Eigen)
  target_precompile_headers(reconar_test_pch_host PRIVATE
      <gtest/gtest.h> <Eigen/Dense>
      <algorithm> <array> <cmath> <cstdint> <cstdio> <filesystem> <fstream> <functional> <map>
      <memory> <random> <set> <sstream> <string> <utility> <vector>)
  set_target_properties(reconar_test_pch_host PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/tests/support")
endfunction()

# reconar_add_test(NAME SOURCES ... [LINKS ...] [LABELS ...] [TIMEOUT seconds] [COST weight] [NO_PCH]
#                  [ONE_PROCESS] [NATIVE_ONLY gtest-pattern ...])
# COST: ctest starts tests of higher cost first, so that long ones (e.g. under qemu) overlap the
# short ones instead of trailing at the end of a parallel run.
# A GoogleTest executable; each TEST becomes a CTest case (discovered through the cross emulator too).
# Label "unit" for fast self-contained tests, "e2e" for tests on ../shared/data.
# ONE_PROCESS: the executable is one CTest case (named NAME) running all its tests in one process,
# for tests that share a scene built once per process (SetUpTestSuite, a static built on first use):
# one case per TEST would build it again in every case.
# NATIVE_ONLY: the unit tests matching these GoogleTest patterns (e.g. Suite.Name*) are labelled
# "native" instead: self-contained, run by scripts/test.sh but not by the qemu run (-L unit). Only
# for tests that check nothing architecture-specific that another unit test does not check under
# qemu (the SIMD kernels' own tests, a lighter run of the same code path), and that take a minute
# or more there.
function(reconar_add_test name)
  # RESOURCE_LOCK: tests holding the same lock never run at the same time (x_screen: they show
  # windows on, or read back, the one X server's screen under xvfb-run).
  cmake_parse_arguments(ARG "NO_PCH;ONE_PROCESS" "TIMEOUT;COST;RESOURCE_LOCK" "SOURCES;LINKS;LABELS;NATIVE_ONLY"
                        ${ARGN})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  # The cross build runs only `unit` tests (under qemu); it need not compile the others.
  if(NOT RECONAR_BUILD_E2E_TESTS AND NOT "unit" IN_LIST ARG_LABELS)
    return()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LINKS})  # before GoogleTest, as the linker wants them
  reconar_test_compile_settings(${name})
  # The allocation tests compile Eigen with its heap guard and assertions on: not the shared header.
  if(TARGET reconar_test_pch_host AND NOT ARG_NO_PCH AND NOT "reconar_allocation_counter" IN_LIST ARG_LINKS)
    target_precompile_headers(${name} REUSE_FROM reconar_test_pch_host)
  endif()
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/tests")
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  set(lock)
  if(ARG_RESOURCE_LOCK)
    set(lock RESOURCE_LOCK ${ARG_RESOURCE_LOCK})
  endif()
  # The GoogleTest filters of the two sets: every test but the native-only ones, and those.
  set(native_filter)
  if(ARG_NATIVE_ONLY)
    if(NOT "unit" IN_LIST ARG_LABELS)
      message(FATAL_ERROR "${name}: NATIVE_ONLY is for unit tests")
    endif()
    # Discovery with a filter (TEST_FILTER) is CMake 3.22's; an older CMake runs them all as unit.
    if(NOT CMAKE_VERSION VERSION_LESS 3.22)
      list(JOIN ARG_NATIVE_ONLY ":" native_filter)
    endif()
  endif()
  set(native_labels "${ARG_LABELS}")
  list(TRANSFORM native_labels REPLACE "^unit$" native)
  if(ARG_ONE_PROCESS)
    set(rest_filter)
    if(native_filter)
      set(rest_filter "--gtest_filter=-${native_filter}")
    endif()
    add_test(NAME ${name} COMMAND ${name} ${rest_filter})
    set_tests_properties(${name} PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT} COST ${ARG_COST} ${lock})
    if(native_filter)
      add_test(NAME ${name}_native COMMAND ${name} "--gtest_filter=${native_filter}")
      set_tests_properties(${name}_native PROPERTIES LABELS "${native_labels}" TIMEOUT ${ARG_TIMEOUT}
                           COST ${ARG_COST} ${lock})
    endif()
    return()
  endif()
  set(rest_filter)
  if(native_filter)
    set(rest_filter TEST_FILTER "-${native_filter}")
  endif()
  gtest_discover_tests(${name} ${rest_filter}
      PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT} COST ${ARG_COST} ${lock}
      DISCOVERY_TIMEOUT 120)
  if(native_filter)
    gtest_discover_tests(${name} TEST_FILTER "${native_filter}"
        PROPERTIES LABELS "${native_labels}" TIMEOUT ${ARG_TIMEOUT} COST ${ARG_COST} ${lock}
        DISCOVERY_TIMEOUT 120)
  endif()
endfunction()
