// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// The PCD result output of pcd_collision (pcl/io/pcd_io.h stays in pcd_files.cpp); point-cloud
// input is io/cloud_input.h.

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>
#include <vector>

namespace pcd_collision
{
/** \brief One side of the -o output. */
struct LabelledCloud
{
  const pcl::PointCloud<pcl::PointXYZ>* cloud = nullptr;  ///< already in the output frame
  const std::vector<float>* probabilities = nullptr;     ///< per point (NaN = not evaluated); may be null
  std::uint32_t label = 0;
};

/** \brief Writes the sides one after the other as a binary PCD with fields x y z intensity
  * (probability) rgb (verdict colour under the request's thresholds, verdictFor()) label, atomically: a temporary file
  * in the target directory, then rename (removed on failure). False with a reason on failure. */
bool writeResultCloud (const std::string& path, const std::vector<LabelledCloud>& sides,
                       const pcl_probcollision::CollisionRequest& request, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                       std::size_t& points_written, std::string& error);

/** \brief Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary file of a
  * writeResultCloud in progress and then die of the same signal (exit status 128 + n to a
  * shell). Signals that were ignored at start stay ignored. */
void installInterruptCleanup ();

/** \brief The colour of a verdict, packed as PCL's rgb (0x00RRGGBB): free green, contact
  * yellow, collision red, Unknown (not evaluated) grey. */
std::uint32_t verdictColour (pcl_probcollision::Verdict verdict);
} // namespace pcd_collision
