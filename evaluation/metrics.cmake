# SPDX-License-Identifier: BSD-3-Clause
# Metrics (ROC AUC, Brier, reliability bins, percentiles, flip rate, Pareto front) and the
# analytic primitives workload W2 (noisy samples, closed-form signed distances).
add_library(eval_metrics STATIC
  ${CMAKE_CURRENT_LIST_DIR}/metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/primitives.cpp)
target_include_directories(eval_metrics PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(eval_metrics PUBLIC pcl_probcollision pcl_common Eigen3::Eigen)
target_compile_options(eval_metrics PRIVATE -Wall -Wextra)

if(BUILD_TESTING)
  # test/ found GTest in its own directory scope; imported targets are not visible here.
  find_package(GTest REQUIRED)
  include(GoogleTest)
  add_executable(test_metrics ${CMAKE_CURRENT_LIST_DIR}/test_metrics.cpp)
  # pcl_kdtree: the brute-force nearest-neighbour check of the closed-form distances.
  target_link_libraries(test_metrics PRIVATE eval_metrics pcl_kdtree GTest::gtest GTest::gtest_main)
  target_compile_options(test_metrics PRIVATE -Wall -Wextra)
  gtest_discover_tests(test_metrics TEST_PREFIX "eval." DISCOVERY_TIMEOUT 60)
endif()
