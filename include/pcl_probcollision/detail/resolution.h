// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>

#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Samples grouped by noiseClusters(): which cluster each sample joined, and the seed of
  * each cluster (the sample it was grown from). */
struct NoiseClusters
{
  /** \brief Per sample (index into the positions given), its cluster in [0, seeds.size()). */
  std::vector<int> cluster_of;
  /** \brief Per cluster, the sample it was grown from; clusters are numbered in seed order. */
  std::vector<int> seeds;
  /** \brief True when at least one cluster has more than one sample. */
  bool merged () const { return seeds.size () < cluster_of.size (); }
};

/** \brief Greedy clustering of samples closer than their noise (CloudModelParams::noise_resolution):
  * samples are visited in the order given; each one not yet in a cluster seeds a new cluster
  * and takes every sample not yet in a cluster within radii[seed] of it (k-d tree radius
  * search, pcl::KdTreeFLANN). Serial, so the result depends only on the input (not on threads),
  * and invariant under rigid motion of the samples.
  * \param[in] positions the samples (finite)
  * \param[in] radii per sample, the merge radius when it seeds a cluster (0: it merges nothing)
  * \return the clusters; cluster_of is empty only for no sample */
NoiseClusters
noiseClusters (const std::vector<Eigen::Vector3f>& positions, const std::vector<float>& radii);
} // namespace detail
} // namespace pcl_probcollision
