# SPDX-License-Identifier: BSD-3-Clause
# The driver: every method on every workload, CSV out (scripts/evaluate.sh renders the charts).
add_executable(evaluate_collision evaluate_collision.cpp workloads.cpp scenes.cpp fit_scenes.cpp)
# pcd_collision_cli: the command-line tool's number parsing (one reader of a number on a command line),
# under eval_options.h, the evaluation tools' option readers (evaluate_collision, dump_primitive,
# bench_performance).
target_link_libraries(evaluate_collision PRIVATE eval_ground_truth eval_metrics pcl_probcollision_io pcd_collision_cli
  pcl_probcollision pcl_io FLANN::FLANN)
target_compile_options(evaluate_collision PRIVATE -Wall -Wextra)

# The drift of the maximum with the number of points (docs/RESULTS.md, calibration).
add_executable(calibration_drift calibration_drift.cpp)
target_link_libraries(calibration_drift PRIVATE pcl_probcollision)
target_compile_options(calibration_drift PRIVATE -Wall -Wextra)

# Issue #8's figures (docs/PERFORMANCE.md): build, query and batch times beside the octomap and
# exact-mesh references on the same poses. Prints counters; asserts nothing.
find_package(benchmark QUIET)
if(benchmark_FOUND)
  add_executable(bench_performance bench_performance.cpp workloads.cpp)
  target_link_libraries(bench_performance PRIVATE eval_ground_truth eval_metrics pcl_probcollision_io
    pcd_collision_cli pcl_probcollision benchmark::benchmark)
  target_compile_options(bench_performance PRIVATE -Wall -Wextra)
  target_compile_definitions(bench_performance PRIVATE
    PCL_PROBCOLLISION_SHARED_DATA="${PCL_PROBCOLLISION_SHARED_DATA}")
  if(BUILD_TESTING)
    # A bad setting is one line naming it, before any benchmark runs (it was "terminate called").
    add_test(NAME eval.BenchPerformanceRefusesABadNoise
      COMMAND ${CMAKE_COMMAND} -E env BENCH_PERFORMANCE_NOISE=1O $<TARGET_FILE:bench_performance>)
    set_tests_properties(eval.BenchPerformanceRefusesABadNoise PROPERTIES PASS_REGULAR_EXPRESSION
      "^bench_performance: BENCH_PERFORMANCE_NOISE [^\n]*'1O' is not a finite number\n$")
    add_test(NAME eval.BenchPerformanceRefusesAnUnknownSetting
      COMMAND ${CMAKE_COMMAND} -E env BENCH_PERFORMANCE_SETTING=bogus $<TARGET_FILE:bench_performance>)
    set_tests_properties(eval.BenchPerformanceRefusesAnUnknownSetting PROPERTIES PASS_REGULAR_EXPRESSION
      "^bench_performance: BENCH_PERFORMANCE_SETTING: unknown setting 'bogus'\n$")
  endif()
endif()

# One W2 query's clouds as PCD files, to run it alone through pcd_collision (docs/PERFORMANCE.md).
add_executable(dump_primitive dump_primitive.cpp)
target_link_libraries(dump_primitive PRIVATE eval_metrics pcd_collision_cli pcl_io)
target_compile_options(dump_primitive PRIVATE -Wall -Wextra)
if(BUILD_TESTING)
  # The resting-contact query of the first scenario: its name, both clouds and an exact 0 gap.
  add_test(NAME eval.DumpPrimitiveWritesOneQuery
    COMMAND dump_primitive --out ${CMAKE_CURRENT_BINARY_DIR}/dump_primitive_test --seed 1 sphere_sphere/0s)
  set_tests_properties(eval.DumpPrimitiveWritesOneQuery PROPERTIES PASS_REGULAR_EXPRESSION
    "^sphere_sphere/0s: robot [1-9][0-9]* points, env [1-9][0-9]* points, exact distance 0 m; pcd_collision ")
  add_test(NAME eval.EvaluateCollisionChecksItsOptions
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:evaluate_collision> -DDATA=${PCL_PROBCOLLISION_SHARED_DATA}
      -DWORK=${CMAKE_CURRENT_BINARY_DIR}/check_options -P ${CMAKE_CURRENT_SOURCE_DIR}/check_options.cmake)
  # Every case is refused at once or fails reading an empty --data: a value taken by mistake
  # would start a full run instead, which the timeout ends.
  set_tests_properties(eval.EvaluateCollisionChecksItsOptions PROPERTIES TIMEOUT 120)
  add_test(NAME eval.DumpPrimitiveRefusesABadSeed
    COMMAND dump_primitive --out ${CMAKE_CURRENT_BINARY_DIR}/dump_primitive_test --seed 5x sphere_sphere/0s)
  set_tests_properties(eval.DumpPrimitiveRefusesABadSeed PROPERTIES PASS_REGULAR_EXPRESSION
    "option --seed: '5x' is not a whole number")
  # Exit statuses and messages: --help 0 with the usage (it was 2), a bad value 2 naming it.
  add_test(NAME eval.DumpPrimitiveChecksItsOptions
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:dump_primitive> -DWORK=${CMAKE_CURRENT_BINARY_DIR}/check_dump_options
      -P ${CMAKE_CURRENT_SOURCE_DIR}/check_dump_options.cmake)
  add_test(NAME eval.DumpPrimitiveRefusesAnUnknownName
    COMMAND dump_primitive --out ${CMAKE_CURRENT_BINARY_DIR}/dump_primitive_test no_such_scenario)
  set_tests_properties(eval.DumpPrimitiveRefusesAnUnknownName PROPERTIES PASS_REGULAR_EXPRESSION
    "no W2 query name starts with 'no_such_scenario'")
endif()
