# Small helpers so every target gets the same warnings and layout.

function(uwscan_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(UWSCAN_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# uwscan_add_library(NAME SOURCES ... DEPS ...)
# Creates uwscan_NAME with alias uwscan::NAME; headers are included as "NAME/foo.hpp".
function(uwscan_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(uwscan_${name} STATIC ${ARG_SOURCES})
  add_library(uwscan::${name} ALIAS uwscan_${name})
  target_include_directories(uwscan_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(uwscan_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  uwscan_set_warnings(uwscan_${name})
  if(UWSCAN_BUILD_TESTS)
    # Every function it compiles for several CPUs is dispatched at run time (the script says why).
    add_test(NAME dispatch.${name} COMMAND ${PROJECT_SOURCE_DIR}/scripts/check_dispatch.sh
                                           $<TARGET_FILE:uwscan_${name}> ${ARG_SOURCES})
  endif()
endfunction()

# uwscan_add_test(NAME SOURCES ... DEPS ...): one GoogleTest executable registered with CTest.
function(uwscan_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE UWSCAN_SOURCE_DIR_FOR_TESTS="${PROJECT_SOURCE_DIR}")
  uwscan_set_warnings(${name})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "UWSCAN_TEST_CACHE=${UWSCAN_TEST_CACHE}"
                                  FIXTURES_REQUIRED uwscan_test_cache)
endfunction()
