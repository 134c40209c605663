# Warning flags for project code only (third-party headers are included as SYSTEM).
set(JVL_WARNING_FLAGS -Wall -Wextra -Wpedantic -Wno-unused-parameter)
if(JVL_WERROR)
  list(APPEND JVL_WARNING_FLAGS -Werror)
endif()
set(JVL_SANITIZER_FLAGS)
if(JVL_SANITIZE)
  set(JVL_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
endif()

# JVL_FUZZ: coverage instrumentation for libFuzzer in all project code (compile only; the fuzz
# targets link the libFuzzer runtime, the other executables the sanitizer runtimes).
set(JVL_FUZZ_FLAGS)
if(JVL_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "JVL_FUZZ needs Clang: configure with CC=clang-14 CXX=clang++-14")
  endif()
  set(JVL_FUZZ_FLAGS -fsanitize=fuzzer-no-link)
endif()

function(jvl_apply_flags target)
  target_compile_options(${target} PRIVATE ${JVL_WARNING_FLAGS} ${JVL_SANITIZER_FLAGS}
                         ${JVL_FUZZ_FLAGS})
  if(JVL_SANITIZE)
    target_link_options(${target} PRIVATE ${JVL_SANITIZER_FLAGS})
  endif()
endfunction()

# jvl_add_library(NAME name SOURCES ... DEPS ...)
# Creates target jvl_<name> (alias jvl::<name>); headers are included as "<name>/foo.h".
function(jvl_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_library(jvl_${ARG_NAME} STATIC ${ARG_SOURCES})
  add_library(jvl::${ARG_NAME} ALIAS jvl_${ARG_NAME})
  target_include_directories(jvl_${ARG_NAME} PUBLIC ${CMAKE_SOURCE_DIR}/libs)
  target_link_libraries(jvl_${ARG_NAME} PUBLIC ${ARG_DEPS})
  jvl_apply_flags(jvl_${ARG_NAME})
  if(JVL_SANITIZE)
    target_link_options(jvl_${ARG_NAME} INTERFACE ${JVL_SANITIZER_FLAGS})
  endif()
endfunction()

# jvl_add_tool(NAME name SOURCES ... DEPS ...): an executable in bin/.
function(jvl_add_tool)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS})
  jvl_apply_flags(${ARG_NAME})
endfunction()

# jvl_add_test(NAME name SOURCES ... DEPS ... [LABELS ...] [TIMEOUT s])
# A GoogleTest binary registered with CTest; tests run from the source root so that
# ../shared/data resolves as it does for a user.
function(jvl_add_test)
  if(NOT JVL_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME;TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${ARG_NAME} PRIVATE
    JVL_SOURCE_DIR="${CMAKE_SOURCE_DIR}" JVL_BINARY_DIR="${CMAKE_BINARY_DIR}")
  jvl_apply_flags(${ARG_NAME})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_test(NAME ${ARG_NAME} COMMAND ${ARG_NAME} WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(${ARG_NAME} PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}")
endfunction()

# jvl_add_benchmark(NAME name SOURCES ... DEPS ...)
function(jvl_add_benchmark)
  if(NOT JVL_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} benchmark::benchmark)
  jvl_apply_flags(${ARG_NAME})
endfunction()

# jvl_add_fuzzer(NAME name SOURCES ... DEPS ... CORPUS dir [ARGS libFuzzer flags...]): a
# libFuzzer target (JVL_FUZZ only) and a CTest entry "<name>_run" (label "fuzz") that fuzzes
# for JVL_FUZZ_SECONDS from the committed seed corpus `dir`.
set(JVL_FUZZ_SECONDS 15 CACHE STRING "Seconds per fuzz target in the CTest fuzz runs")
function(jvl_add_fuzzer)
  if(NOT JVL_FUZZ)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME;CORPUS" "SOURCES;DEPS;ARGS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS})
  target_compile_definitions(${ARG_NAME} PRIVATE JVL_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
  jvl_apply_flags(${ARG_NAME})
  target_link_options(${ARG_NAME} PRIVATE -fsanitize=fuzzer)
  add_test(NAME ${ARG_NAME}_run
    COMMAND ${CMAKE_SOURCE_DIR}/tests/fuzz/run_fuzzer.sh $<TARGET_FILE:${ARG_NAME}> ${ARG_CORPUS}
            ${CMAKE_BINARY_DIR}/fuzz/${ARG_NAME} ${JVL_FUZZ_SECONDS} ${ARG_ARGS})
  set_tests_properties(${ARG_NAME}_run PROPERTIES LABELS fuzz
    TIMEOUT 300)
endfunction()
