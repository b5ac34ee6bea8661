# SPDX-License-Identifier: BSD-3-Clause
# Installs the already-built project into a scratch prefix, configures and builds the consumer
# in test/downstream against it, and runs the consumer. Any failing step fails the test.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install "${BINARY_DIR}" --prefix "${prefix}")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/test/downstream" -B "${WORK_DIR}/build"
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/downstream")
message(STATUS "downstream consumer built with find_package and ran against ${prefix}")

# The same consumer built without CMake, from the installed pkg-config file alone (moved with the
# prefix: its paths are relative to the file).
file(GLOB pc_dirs "${prefix}/lib*/pkgconfig" "${prefix}/lib/*/pkgconfig")
list(JOIN pc_dirs ":" pc_path)
set(ENV{PKG_CONFIG_PATH} "${pc_path}")
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs pcl_probcollision RESULT_VARIABLE rc OUTPUT_VARIABLE flags
                ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs pcl_probcollision failed (${rc}) with PKG_CONFIG_PATH ${pc_path}:\n${err}")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
run(${CXX} -std=c++17 -O1 "${SOURCE_DIR}/test/downstream/main.cpp" -o "${WORK_DIR}/downstream_pkg_config" ${flags})
run("${WORK_DIR}/downstream_pkg_config")
message(STATUS "downstream consumer built with pkg-config and ran against ${prefix}")
