// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/detail/resolution.h>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>

namespace pcl_probcollision
{
namespace detail
{
NoiseClusters
noiseClusters (const std::vector<Eigen::Vector3f>& positions, const std::vector<float>& radii)
{
  NoiseClusters out;
  const std::size_t n = positions.size ();
  out.cluster_of.assign (n, -1);
  if (n == 0)
    return out;
  const auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>> ();
  cloud->resize (n);
  for (std::size_t i = 0; i < n; ++i)
    (*cloud)[i].getVector3fMap () = positions[i];
  pcl::KdTreeFLANN<pcl::PointXYZ> tree (false);  // unsorted: the order of a search plays no part
  tree.setInputCloud (cloud);
  pcl::Indices found;
  std::vector<float> distances;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (out.cluster_of[i] >= 0)
      continue;
    const int cluster = static_cast<int> (out.seeds.size ());
    out.seeds.push_back (static_cast<int> (i));
    out.cluster_of[i] = cluster;
    if (!(radii[i] > 0.0f))
      continue;
    tree.radiusSearch ((*cloud)[i], static_cast<double> (radii[i]), found, distances);
    for (const int j : found)
      if (out.cluster_of[static_cast<std::size_t> (j)] < 0)
        out.cluster_of[static_cast<std::size_t> (j)] = cluster;
  }
  return out;
}
} // namespace detail
} // namespace pcl_probcollision
