# Writes OUTPUT: the ctest tests of TEST_BINARY, run in WORKING_DIR: one process per folder of
# TESTS_DIR (tests/io, tests/priors/sr, ...) running that folder's GoogleTest suites.
# Run after every build of the test binary (cmake -P).
# - Every process pays LibTorch's start-up (0.6-0.9 s, 1.5 s under the sanitizers), which one
#   process per suite paid a hundred times.
# - The end-to-end suites of tests/cli run the iesrgs binary for tens of seconds: one process each,
#   so that the cores share them.
# - OpenMP threads wait passively: ctest runs as many processes as cores, and threads spinning at
#   a barrier would take another process's core.
set(listing "${OUTPUT}.json")
execute_process(COMMAND "${TEST_BINARY}" --gtest_list_tests "--gtest_output=json:${listing}"
                OUTPUT_QUIET RESULT_VARIABLE status TIMEOUT 120)
if(NOT status EQUAL 0 OR NOT EXISTS "${listing}")
  message(FATAL_ERROR "${TEST_BINARY} --gtest_list_tests failed: ${status}")
endif()
file(READ "${listing}" json)
file(REMOVE "${listing}")

string(JSON suite_count LENGTH "${json}" testsuites)
if(suite_count EQUAL 0)
  message(FATAL_ERROR "${TEST_BINARY} lists no test suites")
endif()
set(groups "")
math(EXPR last "${suite_count} - 1")
foreach(i RANGE ${last})
  string(JSON suite GET "${json}" testsuites ${i} name)
  # A suite belongs to the folder of its first test's source.
  string(JSON source GET "${json}" testsuites ${i} testsuite 0 file)
  file(RELATIVE_PATH source "${TESTS_DIR}" "${source}")
  get_filename_component(group "${source}" DIRECTORY)
  if(group STREQUAL "")
    set(group "tests")  # a source at the top of tests/
  elseif(group STREQUAL "cli")
    set(group "cli/${suite}")
  endif()
  string(MAKE_C_IDENTIFIER "${group}" key)
  if(NOT DEFINED filter_${key})
    list(APPEND groups "${group}")
    set(filter_${key} "${suite}.*")
  else()
    string(APPEND filter_${key} ":${suite}.*")
  endif()
endforeach()

set(script "")
list(SORT groups)
foreach(group IN LISTS groups)
  string(MAKE_C_IDENTIFIER "${group}" key)
  string(APPEND script
    "add_test([==[${group}]==] [==[${TEST_BINARY}]==] [==[--gtest_filter=${filter_${key}}]==])\n"
    "set_tests_properties([==[${group}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKING_DIR}]==]\n"
    "                                             ENVIRONMENT OMP_WAIT_POLICY=passive)\n")
endforeach()
file(WRITE "${OUTPUT}.tmp" "${script}")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
