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
  * The same for any thread count.
  * \param[in] positions the samples (finite)
  * \param[in] k neighbours (>= 1)
  * \param[in] threads threads of the search (0: one per hardware thread, as CloudModelParams) */
std::vector<float>
localSpacing (const std::vector<Eigen::Vector3f>& positions, int k, int threads = 1);

/** \brief The spacing at a typical place of a surface rather than of a typical sample: the
  * median of per-sample spacings weighted by the area each stands for (its spacing squared), so
  * that half the surface's area lies on samples at most this far apart. A triangle soup's
  * clusters of repeated vertices (spacings far below the noise) weigh as little as the area they
  * cover. One owner for SurfaceModel::surfaceSpacing() and the whole-cloud resolution gate.
  * \param[in] spacings per-sample spacings (sorted in place; non-finite or negative ones ignored)
  * \return the weighted median; 0 for no usable spacing */
double
areaWeightedMedian (std::vector<float>& spacings);

/** \brief Samples each statistic of wholeCloudMerge reads, at most. */
constexpr std::size_t kWholeCloudGateSamples = 65536;

/** \brief The whole-cloud gate's test of a cloud of two densities (WholeCloudMerge::DenseSamples):
  * more than half of its samples at least twice as dense as their noise, spacing^2 at most this
  * times the deviation^2 (two samples or more to each square of the deviation). A cloud sampled
  * evenly about as finely as its noise has almost none, though half or more of its samples lie
  * within the noise itself, since local spacings scatter about their mean (the evaluation's
  * primitives at 4 mm noise, seed 2: 1 % against 54-65 %; its rooms, their triangle soups'
  * repeated vertices among them, at most 29 %); a depth camera's scan of near objects before a
  * far wall has most (../shared/data's Kinect scan: 77 % at 5 mm noise, 61 % at 3 mm).
  * docs/PERFORMANCE.md, "A depth scan's dense samples merged". */
constexpr double kDenseSpacingSquaredPerVariance = 0.5;

/** \brief What the whole-cloud gate (CloudModelParams::ResolutionGate::WholeCloud) merges. */
enum class WholeCloudMerge
{
  None,          ///< neither: nothing merges, the model is the unmerged one
  DenseSamples,  ///< most samples twice as dense as their noise, though not most of the area: those within it merge (as WhereNoiseExceedsSpacing)
  Everything     ///< most of the area sampled finer than its noise: every sample (as Everywhere)
};

/** \brief The whole-cloud gate's decision (CloudModelParams::ResolutionGate::WholeCloud), from
  * each sample's spacing, sqrt(pi / k) times its distance to its k-th neighbour, and its noise's
  * smallest standard deviation:
  * - Everything where the cloud is sampled finer than its noise, its median deviation at least
  *   its area-weighted spacing (areaWeightedMedian: most of the surface's area);
  * - else DenseSamples where more than half of the samples are at least twice as dense as their
  *   noise (kDenseSpacingSquaredPerVariance): a depth camera's scan whose near objects are
  *   sampled a millimetre or two apart and whose far wall, a few samples holding half the area,
  *   tens of millimetres. The samples the spacing gate lets merge (WhereNoiseExceedsSpacing: the
  *   spacing within the noise) then merge, and the wall stays as it was;
  * - else None. Where fewer samples are dense (a triangle soup's repeated vertices among mesh
  *   samples spaced wider than the noise, or a cloud sampled evenly at its noise) merging them
  *   saves less and moves answers both ways: the evaluation's rooms keep every vertex, and
  *   merging those lost easy answers at 0.25-1 % noise (docs/PERFORMANCE.md, "Gated by the
  *   local spacing").
  * The statistics read an evenly strided subsample of at most kWholeCloudGateSamples, so the
  * cost does not grow with the cloud beyond one pass and the decision is the same for any
  * thread count.
  * \param[in] kth_radii per sample, the distance to its k-th nearest neighbour (the covariance
  *            estimation's CovarianceEstimation::getNeighbourRadii; non-finite entries ignored)
  * \param[in] k neighbours those radii were found with (>= 1)
  * \param[in] deviation per sample index, its noise's smallest standard deviation */
template <typename Deviation>
WholeCloudMerge
wholeCloudMerge (const std::vector<float>& kth_radii, int k, const Deviation& deviation)
{
  const std::size_t n = kth_radii.size ();
  if (n == 0 || k < 1)
    return WholeCloudMerge::None;
  const std::size_t stride = (n + kWholeCloudGateSamples - 1) / kWholeCloudGateSamples;
  const double per = std::sqrt (3.14159265358979323846 / static_cast<double> (k));
  std::vector<float> spacings, deviations;
  spacings.reserve (n / stride + 1);
  deviations.reserve (n / stride + 1);
  std::size_t judged = 0, dense = 0;  // samples with both figures; those twice as dense as their noise
  for (std::size_t i = 0; i < n; i += stride)
  {
    const bool has_spacing = std::isfinite (kth_radii[i]);
    const double local = per * kth_radii[i];
    if (has_spacing)
      spacings.push_back (static_cast<float> (local));
    const double d = deviation (i);
    if (!std::isfinite (d))
      continue;
    deviations.push_back (static_cast<float> (d));
    if (has_spacing)
    {
      ++judged;
      dense += d > 0.0 && local * local <= kDenseSpacingSquaredPerVariance * d * d ? 1 : 0;
    }
  }
  if (deviations.empty ())
    return WholeCloudMerge::None;
  const auto middle = deviations.begin () + static_cast<std::ptrdiff_t> (deviations.size () / 2);
  std::nth_element (deviations.begin (), middle, deviations.end ());
  const double spacing = areaWeightedMedian (spacings);
  if (spacing > 0.0 && static_cast<double> (*middle) >= spacing)
    return WholeCloudMerge::Everything;
  return 2 * dense > judged ? WholeCloudMerge::DenseSamples : WholeCloudMerge::None;
}
} // namespace detail
} // namespace pcl_probcollision
