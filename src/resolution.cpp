// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/detail/resolution.h>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace pcl_probcollision
{
namespace detail
{
NoiseClusters
noiseClusters (const std::vector<Eigen::Vector3f>& positions, const std::vector<float>& radii,
               const std::vector<char>* eligible)
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
      if (out.cluster_of[static_cast<std::size_t> (j)] < 0 && (!eligible || (*eligible)[static_cast<std::size_t> (j)]))
        out.cluster_of[static_cast<std::size_t> (j)] = cluster;
  }
  return out;
}

std::vector<float>
localSpacing (const std::vector<Eigen::Vector3f>& positions, int k)
{
  const std::size_t n = positions.size ();
  std::vector<float> spacing (n, 0.0f);
  if (n < 2 || k < 1)
    return spacing;
  const auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>> ();
  cloud->resize (n);
  for (std::size_t i = 0; i < n; ++i)
    (*cloud)[i].getVector3fMap () = positions[i];
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;  // sorted: the last one found is the k-th
  tree.setInputCloud (cloud);
  const int want = static_cast<int> (std::min<std::size_t> (static_cast<std::size_t> (k) + 1, n));
  const double per = std::sqrt (M_PI / static_cast<double> (want - 1));  // want - 1 others found
  pcl::Indices found;
  std::vector<float> distances;
  for (std::size_t i = 0; i < n; ++i)
  {
    // The sample itself is among those found (distance 0), so want - 1 others; duplicates of it
    // count as neighbours at distance 0.
    if (tree.nearestKSearch ((*cloud)[i], want, found, distances) < want)
      continue;
    spacing[i] = static_cast<float> (per * std::sqrt (static_cast<double> (distances.back ())));
  }
  return spacing;
}

double
areaWeightedMedian (std::vector<float>& spacings)
{
  spacings.erase (std::remove_if (spacings.begin (), spacings.end (), [] (float v) { return !(v >= 0.0f) || !std::isfinite (v); }),
                  spacings.end ());
  std::sort (spacings.begin (), spacings.end ());
  double total = 0.0;
  for (const float v : spacings)
    total += static_cast<double> (v) * v;
  double sum = 0.0;
  for (const float v : spacings)
  {
    sum += static_cast<double> (v) * v;
    if (sum >= 0.5 * total)
      return v;
  }
  return 0.0;
}
} // namespace detail
} // namespace pcl_probcollision
