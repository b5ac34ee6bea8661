// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Point-cloud files of pcd_collision: PCD and face-less PLY input, the PCD result output
// (pcl/io/pcd_io.h and ply_io.h stay in pcd_files.cpp).

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>
#include <vector>

namespace pcd_collision
{
/** \brief Loads any PCD with x y z fields into PointXYZ, keeping width/height (organization),
  * NaN points and the VIEWPOINT (sensor_origin_, sensor_orientation_); a .ply (extension
  * case-insensitive) goes through PCL's PLY reader, its camera element giving the viewpoint. x y z
  * of any numeric type are converted. False with a reason naming the file when the file is
  * unreadable, malformed or truncated, has no x y z, or has no points. */
bool loadCloud (const std::string& path, pcl::PointCloud<pcl::PointXYZ>& cloud, std::string& error);

/** \brief True for a .ply file whose header declares vertices and no face: a point cloud, which
  * loadCloud reads. A PLY with faces is a mesh; an unreadable one is left to the mesh loader,
  * which reports it. Reads the header only. */
bool isFacelessPly (const std::string& path);

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
