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
  * \param[in] eligible per sample, whether it may join another's cluster (nullptr: every one;
  *            CloudModelParams::ResolutionGate). A sample not eligible should have radius 0.
  * \return the clusters; cluster_of is empty only for no sample */
NoiseClusters
noiseClusters (const std::vector<Eigen::Vector3f>& positions, const std::vector<float>& radii,
               const std::vector<char>* eligible = nullptr);

/** \brief Local sample spacing (CloudModelParams::ResolutionGate::WhereNoiseExceedsSpacing):
  * per sample, sqrt(pi / k) times the distance to its k-th nearest other sample (k-d tree,
  * pcl::KdTreeFLANN), the square root of the surface area per sample that a disc through the
  * k nearest neighbours covers; for samples spread evenly at spacing h on a surface it is about
  * h. With fewer than k + 1 samples, the farthest other sample's distance is used with their
  * count (0 for a single sample).
  * \param[in] positions the samples (finite)
  * \param[in] k neighbours (>= 1) */
std::vector<float>
localSpacing (const std::vector<Eigen::Vector3f>& positions, int k);
} // namespace detail
} // namespace pcl_probcollision
