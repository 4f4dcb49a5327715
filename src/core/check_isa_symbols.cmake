# Fails when the AVX2 compilation of the CPU kernels (OBJECT) defines a weak symbol outside its
# own namespace: the linker keeps one copy of each weak symbol for the whole program, so baseline
# code could end up running an AVX2-compiled copy (see cpu_isa_variant.hpp). Usage:
#   cmake -DNM=<nm> -DOBJECT=<object file> -P check_isa_symbols.cmake
execute_process(COMMAND ${NM} --defined-only --demangle ${OBJECT} OUTPUT_VARIABLE symbols
                RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${OBJECT}: ${NM} failed")
endif()
string(REPLACE "\n" ";" lines "${symbols}")
set(shared "")
foreach(line IN LISTS lines)
  # Weak code and data (W, V, u); DW.ref.* only points at the C++ personality routine.
  if(line MATCHES "^[0-9a-f]+ [WVu] (.*)$")
    set(name "${CMAKE_MATCH_1}")
    if(NOT name MATCHES "::avx2::|^DW\\.ref\\.")
      string(APPEND shared "\n  ${name}")
    endif()
  endif()
endforeach()
if(shared)
  message(FATAL_ERROR "${OBJECT}: weak symbols outside namespace avx2, which the baseline code "
                      "may share:${shared}")
endif()
