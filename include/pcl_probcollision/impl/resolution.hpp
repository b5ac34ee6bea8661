// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/detail/huge_pages.h>
#include <pcl_probcollision/detail/resolution.h>
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_cloud.h>
#include <pcl/type_traits.h>
#include <pcl/types.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief The smallest standard deviation of noise's covariance at a position (the normal
  * unknown): the merge radius's unit (0 where it is not finite). A model without a sensor pose
  * has one covariance everywhere: one eigen solve then, not one per sample (0.2 s serial on
  * 5,000,000 points, 50,000 solves in every whole-cloud gate). */
class SmallestDeviation
{
public:
  SmallestDeviation (const SensorNoiseModel& noise, const SensorPose& sensor)
    : noise_ (noise), sensor_ (sensor), uniform_ (!noise.usesSensorPose ())
  {
    if (uniform_)
      value_ = solve (Eigen::Vector3d::Zero ());
  }

  double
  operator() (const Eigen::Vector3d& position) const
  {
    return uniform_ ? value_ : solve (position);
  }

private:
  double
  solve (const Eigen::Vector3d& position) const
  {
    const Eigen::Matrix3d sigma = noise_.covariance (position, Eigen::Vector3d::Zero (), sensor_);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect (sigma, Eigen::EigenvaluesOnly);
    const double smallest = eig.eigenvalues ()(0);
    return std::isfinite (smallest) ? std::sqrt (std::max (0.0, smallest)) : 0.0;
  }

  const SensorNoiseModel& noise_;
  SensorPose sensor_;
  bool uniform_;
  double value_ = 0.0;
};

/** \brief Keeps one sample of each exactly coincident group (x y z equal and, for point types
  * with normals, the normal too; -0 and 0 alike): the sample first in the cloud, with its fields.
  * A cloud concatenated with itself, or saved twice over, holds no more information than once,
  * but its duplicates collapse each point's k nearest neighbours and halve its leaves' spread:
  * every point of a stereo scan duplicated moved 27 of 100 near-contact verdicts toward free,
  * collisions 4-5 mm deep to contact (a metamorphic probe, 2026-12-07). Samples at one position
  * with different normals (a mesh's vertex repeated per face) stay apart.
  * \param[in] cloud, indices the samples (non-finite ones are left out)
  * \param[out] distinct the kept samples, in cloud order; the cloud's header and viewpoint
  * \param[out] cluster_of per index of cloud, its point in distinct (-1 when not a sample)
  * \param[out] seeds per point of distinct, its index in cloud
  * \return false, leaving the outputs unspecified, when no two samples coincide */
template <typename PointT>
bool
mergeCoincident (const pcl::PointCloud<PointT>& cloud, const pcl::Indices* indices, pcl::PointCloud<PointT>& distinct,
                 std::vector<int>& cluster_of, std::vector<int>& seeds)
{
  constexpr std::size_t kFields = pcl::traits::has_normal_v<PointT> ? 6 : 3;
  struct Entry
  {
    std::array<std::uint32_t, kFields> key;
    int index;
  };
  const auto bits = [] (float v) {
    v += 0.0f;  // -0 to 0
    std::uint32_t b;
    std::memcpy (&b, &v, sizeof b);
    return b;
  };
  const std::size_t n = indices ? indices->size () : cloud.size ();
  std::vector<Entry> entries;
  entries.reserve (n);
  for (std::size_t j = 0; j < n; ++j)
  {
    const int i = indices ? (*indices)[j] : static_cast<int> (j);
    const PointT& p = cloud[static_cast<std::size_t> (i)];
    if (!pcl::isXYZFinite (p))
      continue;
    Entry e;
    e.index = i;
    e.key[0] = bits (p.x);
    e.key[1] = bits (p.y);
    e.key[2] = bits (p.z);
    if constexpr (pcl::traits::has_normal_v<PointT>)
    {
      e.key[3] = bits (p.normal_x);
      e.key[4] = bits (p.normal_y);
      e.key[5] = bits (p.normal_z);
    }
    entries.push_back (e);
  }
  // Equal keys together, each group in cloud order (indices may list a sample twice: one entry).
  std::sort (entries.begin (), entries.end (),
             [] (const Entry& a, const Entry& b) { return a.key != b.key ? a.key < b.key : a.index < b.index; });
  std::vector<int> seed_of (cloud.size (), -1);  // per index of cloud, the index of its group's first sample
  bool coincide = false;
  for (std::size_t e = 0; e < entries.size ();)
  {
    std::size_t end = e + 1;
    while (end < entries.size () && entries[end].key == entries[e].key)
      ++end;
    for (std::size_t m = e; m < end; ++m)
      seed_of[static_cast<std::size_t> (entries[m].index)] = entries[e].index;
    coincide = coincide || (end - e > 1 && entries[end - 1].index != entries[e].index);
    e = end;
  }
  if (!coincide)
    return false;
  distinct.clear ();
  distinct.header = cloud.header;
  distinct.sensor_origin_ = cloud.sensor_origin_;
  distinct.sensor_orientation_ = cloud.sensor_orientation_;
  seeds.clear ();
  assignHugePages (cluster_of, cloud.size (), -1);
  // In cloud order: a group's seed (its first sample) comes before the rest of it.
  for (std::size_t i = 0; i < cloud.size (); ++i)
    if (seed_of[i] == static_cast<int> (i))
    {
      cluster_of[i] = static_cast<int> (seeds.size ());
      seeds.push_back (static_cast<int> (i));
      distinct.push_back (cloud[i]);
    }
    else if (seed_of[i] >= 0)
      cluster_of[i] = cluster_of[static_cast<std::size_t> (seed_of[i])];
  distinct.width = static_cast<std::uint32_t> (distinct.size ());
  distinct.height = 1;
  distinct.is_dense = true;
  return true;
}

/** \brief Merges the samples of a cloud that lie closer than factor times their sensor noise
  * (CloudModelParams::noise_resolution; clusters by noiseClusters(), each seed's radius factor
  * times the smallest standard deviation of noise's covariance there, the normal unknown).
  * \param[in] cloud, indices the samples (non-finite ones are left out)
  * \param[in] noise the sensor noise model (None merges nothing)
  * \param[in] factor merge radius in noise standard deviations (> 0)
  * \param[in] gate_k 0: every sample may merge (ResolutionGate::Everywhere); k >= 1: only
  *            samples whose localSpacing() with k neighbours is at most their smallest noise
  *            standard deviation (ResolutionGate::WhereNoiseExceedsSpacing)
  * \param[in] threads threads of the gate's spacing search (localSpacing); the result is the
  *            same for any count
  * \param[out] merged one point per cluster: the seed's fields, at the members' centroid, with
  *             the members' mean normal for point types with normals; the cloud's viewpoint
  * \param[out] cluster_of per index of cloud, its merged point (-1 when not a sample)
  * \param[out] seeds per merged point, the index in cloud of its seed
  * \return false, leaving the outputs unspecified, when no two samples merged */
template <typename PointT>
bool
mergeByNoise (const pcl::PointCloud<PointT>& cloud, const pcl::Indices* indices, const SensorNoiseModel& noise,
              double factor, int gate_k, int threads, pcl::PointCloud<PointT>& merged, std::vector<int>& cluster_of,
              std::vector<int>& seeds)
{
  if (noise.type () == SensorNoiseModel::Type::None || !(factor > 0.0))
    return false;
  const std::size_t n = indices ? indices->size () : cloud.size ();
  std::vector<int> source;
  std::vector<Eigen::Vector3f> positions;
  reserveHugePages (source, n);
  reserveHugePages (positions, n);
  for (std::size_t j = 0; j < n; ++j)
  {
    const int i = indices ? (*indices)[j] : static_cast<int> (j);
    if (pcl::isXYZFinite (cloud[i]))
    {
      source.push_back (i);
      positions.push_back (cloud[i].getVector3fMap ());
    }
  }
  const SensorPose sensor = SensorPose::fromViewpoint (cloud.sensor_origin_, cloud.sensor_orientation_);
  std::vector<float> radii;
  assignHugePages (radii, positions.size (), 0.0f);
  std::vector<float> spacing;
  std::vector<char> eligible;
  if (gate_k > 0)
  {
    spacing = localSpacing (positions, gate_k, threads);
    eligible.assign (positions.size (), 0);
  }
  const SmallestDeviation smallestDeviation (noise, sensor);
  for (std::size_t p = 0; p < positions.size (); ++p)
  {
    const double deviation = smallestDeviation (positions[p].cast<double> ());
    if (gate_k > 0)
    {
      // The gate: the noise at least the local spacing (a sample spaced wider never merges).
      if (!(deviation > 0.0 && spacing[p] <= deviation))
        continue;
      eligible[p] = 1;
    }
    radii[p] = static_cast<float> (factor * deviation);
  }
  const NoiseClusters clusters = noiseClusters (positions, radii, gate_k > 0 ? &eligible : nullptr);
  if (!clusters.merged ())
    return false;

  const std::size_t m = clusters.seeds.size ();
  std::vector<Eigen::Vector3d> sums (m, Eigen::Vector3d::Zero ());  // about the seed, for precision
  std::vector<Eigen::Vector3f> normals (m, Eigen::Vector3f::Zero ());
  std::vector<int> counts (m, 0);
  assignHugePages (cluster_of, cloud.size (), -1);
  for (std::size_t p = 0; p < positions.size (); ++p)
  {
    const int c = clusters.cluster_of[p];
    const std::size_t cu = static_cast<std::size_t> (c);
    cluster_of[static_cast<std::size_t> (source[p])] = c;
    sums[cu] += (positions[p] - positions[static_cast<std::size_t> (clusters.seeds[cu])]).template cast<double> ();
    ++counts[cu];
    if constexpr (pcl::traits::has_normal_v<PointT>)
    {
      const PointT& pt = cloud[source[p]];
      const Eigen::Vector3f nrm (pt.normal_x, pt.normal_y, pt.normal_z);
      if (nrm.allFinite ())
        normals[cu] += nrm;
    }
  }
  merged.clear ();
  merged.resize (m);
  merged.width = static_cast<std::uint32_t> (m);
  merged.height = 1;
  merged.is_dense = true;
  merged.header = cloud.header;
  merged.sensor_origin_ = cloud.sensor_origin_;
  merged.sensor_orientation_ = cloud.sensor_orientation_;
  seeds.resize (m);
  for (std::size_t c = 0; c < m; ++c)
  {
    const std::size_t seed = static_cast<std::size_t> (clusters.seeds[c]);
    seeds[c] = source[seed];
    PointT pt = cloud[source[seed]];
    pt.getVector3fMap () = (positions[seed].template cast<double> () + sums[c] / counts[c]).template cast<float> ();
    if constexpr (pcl::traits::has_normal_v<PointT>)
    {
      // The members' mean normal; a cluster whose normals cancel (both faces of a thin sheet)
      // keeps its seed's.
      const float norm = normals[c].norm ();
      if (norm > 1e-3f * counts[c])
      {
        pt.normal_x = normals[c].x () / norm;
        pt.normal_y = normals[c].y () / norm;
        pt.normal_z = normals[c].z () / norm;
      }
    }
    merged[c] = pt;
  }
  return true;
}
} // namespace detail
} // namespace pcl_probcollision
