// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/sensor_noise.h>

#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <cstddef>
#include <optional>
#include <vector>

namespace pcl_probcollision
{
/** \brief The pose of the pinhole sensor that captured an organized cloud (a depth camera's or a
  * rectified stereo pair's image), from its points alone: the rays of one image row lie in a
  * plane through the optical centre, as do one column's, so the centre is where the rows' and
  * columns' planes meet; the rows' planes share the image's horizontal axis, the columns' its
  * vertical one, and the optical axis is across both, pointing at the points. Range noise moves
  * a point along its ray, within both planes. Rigid motions move the estimate with the points,
  * where pcl::transformPointCloud leaves sensor_origin_ and sensor_orientation_ behind.
  * \param[in] points row-major (index v * width + u), non-finite where the pixel has no point
  * \param[in] width, height the image's size
  * \return nullopt unless at least kMinLines rows and as many columns span a plane (a row that
  *         meets one flat surface only is a line, and says nothing), their planes meet in one
  *         point (conditioned, within kMaxMissRelative of the points' median range) and the
  *         points lie in them: a cloud organized otherwise (a lidar's rings are cones) gives none. */
std::optional<SensorPose>
organizedSensorPose (const std::vector<Eigen::Vector3f>& points, std::size_t width, std::size_t height);

/** \brief As above, for a PCL cloud (nullopt for one that is not organized). */
template <typename PointT>
std::optional<SensorPose>
organizedSensorPose (const pcl::PointCloud<PointT>& cloud)
{
  if (!cloud.isOrganized () || cloud.size () != static_cast<std::size_t> (cloud.width) * cloud.height)
    return std::nullopt;
  std::vector<Eigen::Vector3f> points (cloud.size ());
  for (std::size_t i = 0; i < cloud.size (); ++i)
    points[i] = cloud[i].getVector3fMap ();
  return organizedSensorPose (points, cloud.width, cloud.height);
}
} // namespace pcl_probcollision
