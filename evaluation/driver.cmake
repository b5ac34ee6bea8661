# SPDX-License-Identifier: BSD-3-Clause
# The driver: every method on every workload, CSV out (scripts/evaluate.sh renders the charts).
add_executable(evaluate_collision evaluate_collision.cpp workloads.cpp scenes.cpp)
target_link_libraries(evaluate_collision PRIVATE eval_ground_truth eval_metrics pcd_collision_mesh
  pcl_probcollision pcl_io FLANN::FLANN)
target_compile_options(evaluate_collision PRIVATE -Wall -Wextra)

# The drift of the maximum with the number of points (docs/RESULTS.md, calibration).
add_executable(calibration_drift calibration_drift.cpp)
target_link_libraries(calibration_drift PRIVATE pcl_probcollision)
target_compile_options(calibration_drift PRIVATE -Wall -Wextra)
