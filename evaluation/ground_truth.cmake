# SPDX-License-Identifier: BSD-3-Clause
# Ground truth (FCL on meshes, seeded pose workloads) and the baselines (octomap collision map,
# nearest-neighbour threshold, reconstruct then collide). Included by evaluation/CMakeLists.txt
# after find_package(fcl), find_package(octomap) and find_package(PCL ... surface).
# FCL, octomap, FLANN and pcl_surface are private: the public headers need only PCL's point
# cloud, Eigen and io/mesh_input.h.
find_package(Threads REQUIRED)
# FLANN's index headers (baselines.cpp) compile its LZ4 serialisation into the vtables.
find_library(PCL_PROBCOLLISION_LZ4_LIBRARY NAMES lz4)
if(NOT PCL_PROBCOLLISION_LZ4_LIBRARY)
  message(FATAL_ERROR "liblz4 not found (needed by FLANN's headers in evaluation/baselines.cpp)")
endif()

add_library(eval_ground_truth STATIC
  ${CMAKE_CURRENT_LIST_DIR}/ground_truth.cpp
  ${CMAKE_CURRENT_LIST_DIR}/baselines.cpp)
target_include_directories(eval_ground_truth PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_include_directories(eval_ground_truth SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
target_link_libraries(eval_ground_truth
  PUBLIC pcl_probcollision_io pcl_probcollision pcl_common
  PRIVATE fcl ${OCTOMAP_LIBRARIES} pcl_kdtree pcl_search pcl_features pcl_surface
    ${PCL_PROBCOLLISION_LZ4_LIBRARY} Threads::Threads)
target_compile_options(eval_ground_truth PRIVATE -Wall -Wextra)

if(BUILD_TESTING)
  # GTest's imported targets from test/CMakeLists.txt are not visible in this directory.
  find_package(GTest REQUIRED)
  include(GoogleTest)
  add_executable(test_ground_truth ${CMAKE_CURRENT_LIST_DIR}/test_ground_truth.cpp ${CMAKE_CURRENT_LIST_DIR}/fit_scenes.cpp)
  target_link_libraries(test_ground_truth PRIVATE eval_ground_truth GTest::gtest GTest::gtest_main)
  target_compile_options(test_ground_truth PRIVATE -Wall -Wextra)
  target_compile_definitions(test_ground_truth PRIVATE
    PCL_PROBCOLLISION_SHARED_DATA="${PCL_PROBCOLLISION_SHARED_DATA}")
  gtest_discover_tests(test_ground_truth DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "evaluation")
endif()
