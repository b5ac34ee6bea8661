// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/detail/resolution.h>
#include <pcl_probcollision/detail/huge_pages.h>
#include <pcl_probcollision/detail/parallel.h>
#include <pcl_probcollision/impl/covariance_estimation.hpp>  // BatchKdTree

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
  assignHugePages (out.cluster_of, n, -1);
  if (n == 0)
    return out;
  // A uniform grid of cells at least the largest radius wide, so that a search visits three or
  // four cells along each axis. Cells are numbered as in a dense grid over the bounding box,
  // wrapped onto 2n to 4n buckets: neighbouring cells stay close in memory (a k-d tree's radius
  // searches cost 5 times as much on 5,000,000 points, docs/PERFORMANCE.md), and two cells that
  // share a bucket only cost distance tests.
  float largest = 0.0f;
  Eigen::Vector3f lo = positions[0], hi = positions[0];
  for (std::size_t i = 0; i < n; ++i)
  {
    largest = std::max (largest, radii[i]);
    lo = lo.cwiseMin (positions[i]);
    hi = hi.cwiseMax (positions[i]);
  }
  if (!(largest > 0.0f))
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      out.cluster_of[i] = static_cast<int> (i);
      out.seeds.push_back (static_cast<int> (i));
    }
    return out;
  }
  const double extent = (hi - lo).cast<double> ().maxCoeff ();
  const double inverse = 1.0 / std::max (static_cast<double> (largest), 1e-9 * extent);
  const auto cell = [&] (double v, int axis) {
    return static_cast<std::uint64_t> ((std::clamp (v, double (lo[axis]), double (hi[axis])) - lo[axis]) * inverse);
  };
  const std::uint64_t nx = cell (hi.x (), 0) + 1, ny = cell (hi.y (), 1) + 1;
  std::size_t buckets = 1;
  while (buckets < 2 * n)
    buckets <<= 1;
  const std::uint64_t mask = buckets - 1;  // unsigned arithmetic wraps: any cell has a bucket
  const auto bucketOf = [&] (std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    return static_cast<std::size_t> ((x + nx * (y + ny * z)) & mask);
  };

  // Counting sort into buckets; each bucket keeps its samples' positions, and whether each is
  // still free to join a cluster, side by side.
  std::vector<std::uint32_t> first, bucket;
  assignHugePages (first, buckets + 1, 0u);
  resizeHugePages (bucket, n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector3f& p = positions[i];
    bucket[i] = static_cast<std::uint32_t> (bucketOf (cell (p.x (), 0), cell (p.y (), 1), cell (p.z (), 2)));
    ++first[bucket[i] + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b)
    first[b + 1] += first[b];
  std::vector<std::uint32_t> member, slot;
  resizeHugePages (member, n);
  resizeHugePages (slot, n);
  std::vector<Eigen::Vector3f> member_position;
  resizeHugePages (member_position, n);
  std::vector<char> free_to_join;
  assignHugePages (free_to_join, n, char{1});
  {
    std::vector<std::uint32_t> next;
    reserveHugePages (next, buckets);
    next.assign (first.begin (), first.end () - 1);
    for (std::size_t i = 0; i < n; ++i)
    {
      const std::uint32_t s = next[bucket[i]]++;
      member[s] = static_cast<std::uint32_t> (i);
      member_position[s] = positions[i];
      slot[i] = s;
      if (eligible)
        free_to_join[s] = (*eligible)[i];
    }
  }

  for (std::size_t i = 0; i < n; ++i)
  {
    if (out.cluster_of[i] >= 0)
      continue;
    const int cluster = static_cast<int> (out.seeds.size ());
    out.seeds.push_back (static_cast<int> (i));
    out.cluster_of[i] = cluster;
    free_to_join[slot[i]] = 0;
    const float r = radii[i];
    if (!(r > 0.0f))
      continue;
    // FLANN's radius test (pcl::KdTreeFLANN::radiusSearch, L2_Simple): the squared distance
    // summed in float, strictly below the squared radius rounded to float.
    const float squared = static_cast<float> (static_cast<double> (r) * r);
    const Eigen::Vector3f& q = positions[i];
    // The cells searched reach a little past r: a float distance can round below it.
    const double reach = 1.00001 * r;
    std::uint64_t from[3], to[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      from[axis] = cell (q[axis] - reach, axis);
      to[axis] = cell (q[axis] + reach, axis);
    }
    for (std::uint64_t z = from[2]; z <= to[2]; ++z)
      for (std::uint64_t y = from[1]; y <= to[1]; ++y)
        for (std::uint64_t x = from[0]; x <= to[0]; ++x)
        {
          const std::size_t b = bucketOf (x, y, z);
          for (std::uint32_t s = first[b]; s < first[b + 1]; ++s)
          {
            if (!free_to_join[s])
              continue;
            const Eigen::Vector3f& p = member_position[s];
            const float dx = q.x () - p.x (), dy = q.y () - p.y (), dz = q.z () - p.z ();
            float distance = dx * dx;
            distance += dy * dy;
            distance += dz * dz;
            if (distance < squared)
            {
              out.cluster_of[member[s]] = cluster;
              free_to_join[s] = 0;
            }
          }
        }
  }
  return out;
}

std::vector<float>
localSpacing (const std::vector<Eigen::Vector3f>& positions, int k, int threads)
{
  const std::size_t n = positions.size ();
  std::vector<float> spacing (n, 0.0f);
  if (n < 2 || k < 1)
    return spacing;
  const auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>> ();
  cloud->resize (n);
  for (std::size_t i = 0; i < n; ++i)
    (*cloud)[i].getVector3fMap () = positions[i];
  // PCL's k-d tree (pcl::KdTreeFLANN's, so the same neighbours and distances), searched in
  // batches on the build's threads: one query at a time, a 241,407-point scan's build took
  // 605-636 ms instead of 550-558 on two threads (docs/PERFORMANCE.md, "A depth scan's dense
  // samples merged").
  BatchKdTree<pcl::PointXYZ> tree;
  tree.setInputCloud (cloud);
  const std::size_t want = std::min<std::size_t> (static_cast<std::size_t> (k) + 1, n);
  const double per = std::sqrt (M_PI / static_cast<double> (want - 1));  // want - 1 others found
  constexpr std::size_t kChunk = 4096;
  parallelChunks (n, kChunk, threadCount (threads), [&] (std::size_t, std::size_t begin, std::size_t end) {
    // The sample itself is among those found (distance 0), so want - 1 others; duplicates of it
    // count as neighbours at distance 0.
    const std::size_t m = end - begin;
    std::vector<float> queries (3 * m), distances (m * want);
    std::vector<std::size_t> found (m * want);
    for (std::size_t i = begin; i < end; ++i)
      std::copy_n (positions[i].data (), 3, &queries[3 * (i - begin)]);
    tree.nearestKSearch (queries.data (), m, want, found.data (), distances.data ());
    for (std::size_t i = begin; i < end; ++i)
      spacing[i] = static_cast<float> (per * std::sqrt (static_cast<double> (distances[(i - begin) * want + want - 1])));
  });
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
