# SPDX-License-Identifier: BSD-3-Clause
# PCL_PROBCOLLISION_SANITIZE: build every target of this project with sanitizers (docs/RELIABILITY.md).
#   ""                   off (the default)
#   "address,undefined"  AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer included)
#   "thread"             ThreadSanitizer
# Debian's PCL, VTK, FLANN and libgomp are not instrumented: only our code is checked. Any
# undefined-behaviour report aborts (-fno-sanitize-recover) so that ctest sees it as a failure.
set(PCL_PROBCOLLISION_SANITIZE "" CACHE STRING
    "Sanitizers for every target: empty, address,undefined or thread")
set_property(CACHE PCL_PROBCOLLISION_SANITIZE PROPERTY STRINGS "" "address,undefined" "thread")

if(PCL_PROBCOLLISION_SANITIZE)
  set(_pcl_pc_san "${PCL_PROBCOLLISION_SANITIZE}")
  if(_pcl_pc_san MATCHES "thread" AND _pcl_pc_san MATCHES "address")
    message(FATAL_ERROR "PCL_PROBCOLLISION_SANITIZE: thread cannot be combined with address")
  endif()
  if(NOT _pcl_pc_san MATCHES "^(address|undefined|thread|leak)(,(address|undefined|thread|leak))*$")
    message(FATAL_ERROR "PCL_PROBCOLLISION_SANITIZE='${_pcl_pc_san}': expected a comma-separated "
                        "list of address, undefined, leak, thread")
  endif()
  set(_pcl_pc_san_flags -fsanitize=${_pcl_pc_san} -fno-omit-frame-pointer -g)
  if(_pcl_pc_san MATCHES "undefined")
    list(APPEND _pcl_pc_san_flags -fno-sanitize-recover=undefined)
  endif()
  add_compile_options(${_pcl_pc_san_flags})
  if(_pcl_pc_san MATCHES "address")
    # Eigen switches to its hand-made aligned malloc (pointer offset by a header) under
    # __SANITIZE_ADDRESS__, but Debian's PCL was built without it and frees Eigen-allocated
    # PointCloud storage with plain free(): "attempting free on address which was not
    # malloc()-ed" in pcl::io::vtk2mesh. glibc's malloc is 16-byte aligned on x86_64, which is
    # all Eigen needs at its default 16-byte alignment, so keep PCL's choice.
    add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
  add_link_options(-fsanitize=${_pcl_pc_san})
  message(STATUS "pcl_probcollision: sanitizers ${_pcl_pc_san}")
endif()

# Fuzzing (fuzz/): the coverage instrumentation goes on the code the fuzzers exercise only (the
# library, the CLI parser and the fuzzers themselves, fuzz/CMakeLists.txt), not on the test
# programs built in the same tree: it made them about 1.8x slower under ASan.
if(PCL_PROBCOLLISION_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "PCL_PROBCOLLISION_BUILD_FUZZERS needs clang (CC=clang CXX=clang++)")
  endif()
endif()
