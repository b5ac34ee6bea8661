// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Point-cloud input: PCD and face-less PLY files into PointXYZ, with every check a file of
// unknown origin needs (PCL 1.13's PCD reader crashes on a header without FIELDS). Shared by
// pcd_collision and the Python bindings. pcl/io/pcd_io.h and ply_io.h stay in cloud_input.cpp.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

namespace pcl_probcollision
{
namespace io
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
} // namespace io
} // namespace pcl_probcollision
