// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
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
  * and takes every sample not yet in a cluster within radii[seed] of it: squared distance
  * summed in float, strictly below the squared radius rounded to float, as
  * pcl::KdTreeFLANN::radiusSearch tests it. The search is a uniform grid of cells the largest
  * radius wide (linear time and memory). Serial, so the result depends only on the input (not on
  * threads), and invariant under rigid motion of the samples up to float rounding.
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

/** \brief The spacing at a typical place of a surface rather than of a typical sample: the
  * median of per-sample spacings weighted by the area each stands for (its spacing squared), so
  * that half the surface's area lies on samples at most this far apart. A triangle soup's
  * clusters of repeated vertices (spacings far below the noise) weigh as little as the area they
  * cover. One owner for SurfaceModel::surfaceSpacing() and the whole-cloud resolution gate.
  * \param[in] spacings per-sample spacings (sorted in place; non-finite or negative ones ignored)
  * \return the weighted median; 0 for no usable spacing */
double
areaWeightedMedian (std::vector<float>& spacings);

/** \brief Samples each statistic of noiseExceedsTypicalSpacing reads, at most. */
constexpr std::size_t kWholeCloudGateSamples = 65536;

/** \brief CloudModelParams::ResolutionGate::WholeCloud: whether a cloud is sampled finer than
  * its noise, its median noise deviation at least its area-weighted spacing (areaWeightedMedian
  * of sqrt(pi / k) times each sample's distance to its k-th neighbour). Both statistics read an
  * evenly strided subsample of at most kWholeCloudGateSamples, so the cost does not grow with
  * the cloud beyond one pass and the decision is the same for any thread count.
  * \param[in] kth_radii per sample, the distance to its k-th nearest neighbour (the covariance
  *            estimation's CovarianceEstimation::getNeighbourRadii; non-finite entries ignored)
  * \param[in] k neighbours those radii were found with (>= 1)
  * \param[in] deviation per sample index, its noise's smallest standard deviation */
template <typename Deviation>
bool
noiseExceedsTypicalSpacing (const std::vector<float>& kth_radii, int k, const Deviation& deviation)
{
  const std::size_t n = kth_radii.size ();
  if (n == 0 || k < 1)
    return false;
  const std::size_t stride = (n + kWholeCloudGateSamples - 1) / kWholeCloudGateSamples;
  const double per = std::sqrt (3.14159265358979323846 / static_cast<double> (k));
  std::vector<float> spacings, deviations;
  spacings.reserve (n / stride + 1);
  deviations.reserve (n / stride + 1);
  for (std::size_t i = 0; i < n; i += stride)
  {
    if (std::isfinite (kth_radii[i]))
      spacings.push_back (static_cast<float> (per * kth_radii[i]));
    const double d = deviation (i);
    if (std::isfinite (d))
      deviations.push_back (static_cast<float> (d));
  }
  if (deviations.empty ())
    return false;
  const auto middle = deviations.begin () + static_cast<std::ptrdiff_t> (deviations.size () / 2);
  std::nth_element (deviations.begin (), middle, deviations.end ());
  const double spacing = areaWeightedMedian (spacings);
  return spacing > 0.0 && static_cast<double> (*middle) >= spacing;
}
} // namespace detail
} // namespace pcl_probcollision
