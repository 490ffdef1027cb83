# Small helpers so that every component's CMakeLists.txt reads the same way.
#
#   iplan_add_test(NAME SOURCES a.cc b.cc LIBS iplan::foo [LABELS unit] [TIMEOUT s])
#   iplan_add_benchmark(NAME SOURCES a.cc LIBS iplan::foo)
#
# Tests are GoogleTest executables registered with CTest; benchmarks are
# Google Benchmark (or plain) executables that are built but never run by CTest:
# speed targets live in benchmarks, not in timed tests.
include_guard(GLOBAL)

function(iplan_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${IPLAN_TEST_BIN_DIR})
  target_compile_definitions(${name} PRIVATE
    IPLAN_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    IPLAN_SHARED_DIR="${IPLAN_SHARED_DIR}"
    IPLAN_BIN_DIR="${IPLAN_BIN_DIR}")
  add_test(NAME ${name} COMMAND ${name})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  set_tests_properties(${name} PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT})
  # Multi-process tests measure timing (liveliness, deadlines) on a 2-core
  # machine. They spend most of their time waiting (measured: 0.2 to 0.6 of
  # a core on average, eval_interaction one core), so scripts/test.sh runs
  # ctest with two slots per core and each of them takes two: at most two
  # multi-process tests run at once, never a third beside them.
  if("integration" IN_LIST ARG_LABELS)
    set_tests_properties(${name} PROPERTIES PROCESSORS 2)
  endif()
  iplan_test_code(${name})
endfunction()

# Test code (the tests' own sources, probes, forgers) is built with -O1 in
# Release: its speed is never measured (the libraries and services it drives
# keep the Release flags), and -O3 spends about a third of its build time
# optimising it.
function(iplan_test_code target)
  target_compile_options(${target} PRIVATE $<$<CONFIG:Release>:-O1>)
endfunction()

function(iplan_add_benchmark name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${IPLAN_BENCH_BIN_DIR})
  target_compile_definitions(${name} PRIVATE
    IPLAN_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    IPLAN_SHARED_DIR="${IPLAN_SHARED_DIR}"
    IPLAN_BIN_DIR="${IPLAN_BIN_DIR}")
endfunction()
