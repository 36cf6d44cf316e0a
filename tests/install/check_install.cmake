# ctest "install": installs the build into a fresh prefix, configures and builds the consumer
# project against it with find_package(febemesh), and runs it on a bundled example.
# cmake -DBUILD=<build dir> -DSOURCE=<source dir> -DWORK=<scratch dir> -DCXX=<compiler>
#       -DLAUNCHER=<ccache or empty> [-DSANITIZE=ON] -P check_install.cmake
# With SANITIZE (the sanitizer build) the consumer is built with the same -fsanitize flags: the
# installed static libraries are instrumented and need the sanitizer runtimes at link time.
file(REMOVE_RECURSE "${WORK}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD}" --prefix "${WORK}/prefix")
set(sanitize_flags "")
if(SANITIZE)
  set(sanitize_flags "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -fno-omit-frame-pointer"
                     "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
endif()
run(${CMAKE_COMMAND} -S "${SOURCE}/tests/install/consumer" -B "${WORK}/build" -G Ninja
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK}/prefix -DCMAKE_CXX_COMPILER=${CXX}
    -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER} ${sanitize_flags})
run(${CMAKE_COMMAND} --build "${WORK}/build")
run("${WORK}/build/consumer" "${SOURCE}/examples/flange.json")
message(STATUS "consumer meshed the flange: ${last_output}")
file(REMOVE_RECURSE "${WORK}")
