# The CUDA kernels against the CPU ones (tests/<concern>/cuda/): a binary of its own, linked
# without LibTorch, so that a GPU machine builds it with IESRGS_KERNELS_ONLY. Its tests skip where
# no CUDA device can be used.
find_package(GTest REQUIRED)
file(GLOB IESRGS_CUDA_TEST_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*/cuda/*_test.cpp)
add_executable(iesrgs_cuda_tests ${IESRGS_CUDA_TEST_SOURCES})
target_include_directories(iesrgs_cuda_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(iesrgs_cuda_tests PRIVATE iesrgs_cuda GTest::gtest GTest::gtest_main)
add_test(NAME iesrgs_cuda_tests COMMAND iesrgs_cuda_tests)
# Its host reference of the Adam step, compiled as src/gs/optimizer.cpp is: without fused
# multiply-adds, which a native build would make, so that the bits can be compared.
set_property(SOURCE ${CMAKE_CURRENT_LIST_DIR}/gs/cuda/adam_test.cpp APPEND PROPERTY
             COMPILE_OPTIONS -ffp-contract=off)
