// SPDX-License-Identifier: BSD-3-Clause
#include "leaf_pair_test.h"

#include <pcl_probcollision/normal_distribution.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
/** \brief How far under the maximum so far a pair's start plane must stay for the pair to be
  * passed over unfitted, in standard normal quantiles: its maximum P at most
  * Phi(Phi^-1(best / rho) - kStartPlaneMargin). A fit lowers a separable pair's maximum as a
  * rule, but not always: on random separable pairs it raised it in 1-2 % of them, by under a
  * tenth of a quantile above 1e-6 (RobustClassifier.AFitDoesNotRaiseASeparableStartPlanesMaximum).
  * Of the 16,800 answers of the quick evaluation's W1 runs (seeds 2-4) one moved, in the
  * paper's `max` setting: P 0.0240 -> 0.0233, a passed-over pair's fit more than one quantile
  * above its start (docs/PERFORMANCE.md). */
constexpr double kStartPlaneMargin = 1.0;
/** \brief A pair whose start plane leaves every point under this z (P_i = Phi(z_i) < 0.977) is
  * set aside and fitted after the pairs above it: it rarely decides a collision (a fit as a
  * rule lowers its start's maximum), and fitted last it is often passed over. */
constexpr double kSetAsideBelowZ = 2.0;
/** \brief Set-aside pairs are fitted once this many wait, so that the traversal's own pruning
  * (reach weights under the maximum so far) does not wait for the end of the traversal. */
constexpr std::size_t kSetAsideCap = 128;

// Keeps the larger of a stored per-point value and a new one; NaN means "not reached yet".
void
keepMax (float& slot, double value)
{
  const float v = static_cast<float> (value);
  if (std::isnan (slot) || v > slot)
    slot = v;
}
} // namespace

LeafPairTest::LeafPairTest (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b,
                            const CollisionRequest& request, const RobustClassifier& classifier,
                            CollisionResult& result, bool skip_dominated)
  : a_ (a), b_ (b), T_a_b_ (T_a_b), request_ (request), classifier_ (classifier), result_ (result),
    skip_dominated_ (skip_dominated)
{
  // request.defer_kernel_fits: the Ladder's kernel rungs cost a hundred planes. The traversal
  // fits the plane of every leaf pair it reaches; a pair whose plane asks for a kernel rung
  // (RobustClassifier::needsKernel) is set aside, contributing nothing yet, and fitted in full
  // afterwards, largest reach weight first, unless the maximum by then makes it irrelevant.
  // Every pair fitted ends with the fit of a direct Ladder classify(), so without an early stop
  // the maximum is the same; with one (P > collision_above, a lower bound either way) the
  // traversal may stop at a shallower pair before any kernel fit, and P is a lower bound
  // below the default's.
  lazy_kernel_ = request.defer_kernel_fits && !request.per_point && classifier.getParams ().kernel == KernelMode::Ladder;
  // detail/start_plane.h mirrors classify()'s start and its pass-over test for the plane rungs and the
  // default loss; otherwise every pair goes to classify() as it comes.
  assess_starts_ = skip_dominated && classifier.getParams ().kernel != KernelMode::RFF &&
                   classifier.getParams ().loss == Loss::SquaredHinge;
  C_ = classifier.getParams ().C;
  if (request.per_point)
  {
    constexpr float kNotReached = std::numeric_limits<float>::quiet_NaN ();
    result.probabilities_a.assign (a.size (), kNotReached);
    result.probabilities_b.assign (b.size (), kNotReached);
  }
}

bool
LeafPairTest::fit (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, KernelMode kernel,
                   double skip_at_or_below)
{
  const PointSetView view_a = a_.gatherPoints (leaf_a, means_a_, covs_a_);
  const PointSetView view_b = b_.gatherPoints (leaf_b, T_a_b_, means_b_, covs_b_);
  if (classifier_.classify (view_a, view_b, leaf_, kernel, skip_at_or_below, request_.per_point))
    return true;
  if (failure_.empty ())
    failure_ = leaf_.message;
  ++failures_;
  return false;
}

double
LeafPairTest::record (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho,
                      bool count)
{
  CollisionResult& result = result_;
  result.leaf_pairs_tested += count ? 1 : 0;
  result.classifier_iterations += static_cast<std::size_t> (leaf_.iterations);
  result.kernel_leaf_pairs += leaf_.rung == Rung::RFF || leaf_.rung == Rung::RFFLarge ? 1 : 0;
  result.degenerate_leaf_pairs += leaf_.degenerate ? 1 : 0;
  const auto span_a = a_.indices (leaf_a);
  const auto span_b = b_.indices (leaf_b);
  if (request_.per_point)
  {
    for (std::size_t i = 0; i < span_a.size; ++i)
      keepMax (result.probabilities_a[span_a[i]], rho * leaf_.probabilities_a[i]);
    for (std::size_t j = 0; j < span_b.size; ++j)
      keepMax (result.probabilities_b[span_b[j]], rho * leaf_.probabilities_b[j]);
  }
  const double contribution = rho * leaf_.probability;
  if (contribution > best_)
  {
    best_ = contribution;
    const bool on_a = leaf_.witness_side > 0;
    const int local = on_a ? span_a[leaf_.witness_index] : span_b[leaf_.witness_index];
    result.witness_side = on_a ? 1 : -1;
    result.witness_index = (on_a ? a_ : b_).sourceIndex (local);
    result.witness_point = on_a ? means_a_[leaf_.witness_index] : means_b_[leaf_.witness_index];
    result.witness_normal = leaf_.witness_normal;
  }
  return contribution;
}

double
LeafPairTest::skipBelow (double rho)
{
  if (!skip_dominated_ || best_ < 0.0 || !(rho > 0.0))
    return -1.0;
  const double bound = std::min (1.0, best_ / rho);
  if (bound != skip_bound_)
  {
    skip_bound_ = bound;
    skip_below_ = normalCdf (normalQuantile (bound) - kStartPlaneMargin);
  }
  return skip_below_;
}

double
LeafPairTest::operator() (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho)
{
  // What the traversal is told besides a pair's own P_leaf: the largest fitted contribution so
  // far, a lower bound of the final maximum, for its pruning (reach weight <= the maximum).
  // Rounded down by two steps, so that rho times it stays under best_ (the maximum collide()
  // reports is best_ itself).
  const auto so_far = [&] {
    return best_ > 0.0 && rho > 0.0 ? std::nextafter (std::nextafter (std::min (1.0, best_ / rho), 0.0), 0.0) : 0.0;
  };
  if (starts_stopped_)
    return so_far ();  // a set-aside pair already decided the collision
  // A pair that cannot raise the maximum is not fitted (RobustClassifier::classify's
  // skip_at_or_below): its start plane's P stands in, kStartPlaneMargin under best_ / rho.
  const double skip_at_or_below = skipBelow (rho);
  if (assess_starts_)
  {
    const double z = startPlaneZ (a_, leaf_a, b_, leaf_b, T_a_b_);
    if (passesOver (a_, leaf_a, b_, leaf_b, T_a_b_, C_, z, skip_at_or_below))
    {
      ++result_.leaf_pairs_tested;  // tested, as the cap (max_leaf_fits) counts it, not fitted
      return normalCdf (z);
    }
    // The first pair is always fitted: the traversal's pruning needs a maximum to start from.
    if (z < kSetAsideBelowZ && best_ >= 0.0)
    {
      ++result_.leaf_pairs_tested;
      starts_.push_back ({&leaf_a, &leaf_b, rho, z, true});
      if (starts_.size () >= kSetAsideCap)
        starts_stopped_ = flushStarts (request_.collision_above, request_.exhaustive);
      return so_far ();
    }
  }
  if (!fit (leaf_a, leaf_b, lazy_kernel_ ? KernelMode::Linear : classifier_.getParams ().kernel, skip_at_or_below))
    return std::numeric_limits<double>::quiet_NaN ();
  if (leaf_.dominated)
  {
    ++result_.leaf_pairs_tested;  // tested, as the cap (max_leaf_fits) counts it, not fitted
    return leaf_.probability;
  }
  if (lazy_kernel_ && classifier_.needsKernel (leaf_))
  {
    deferred_.push_back ({&leaf_a, &leaf_b, rho, 0.0, false});
    return so_far ();
  }
  record (leaf_a, leaf_b, rho);
  return std::max (leaf_.probability, so_far ());
}

bool
LeafPairTest::flushStarts (double stop_probability, bool exhaustive)
{
  std::stable_sort (starts_.begin (), starts_.end (),
                    [] (const Deferred& x, const Deferred& y) { return x.start_z > y.start_z; });
  bool stopped = false;
  for (const Deferred& d : starts_)
  {
    if (d.rho <= best_)
      continue;  // dominated (assess_starts_ implies skip_dominated_)
    const double skip_at_or_below = skipBelow (d.rho);
    if (passesOver (a_, *d.a, b_, *d.b, T_a_b_, C_, d.start_z, skip_at_or_below))
      continue;
    if (!fit (*d.a, *d.b, lazy_kernel_ ? KernelMode::Linear : classifier_.getParams ().kernel, skip_at_or_below) ||
        leaf_.dominated)
      continue;
    if (lazy_kernel_ && classifier_.needsKernel (leaf_))
    {
      deferred_.push_back (d);
      continue;
    }
    if (record (*d.a, *d.b, d.rho, false) > stop_probability && !exhaustive)
    {
      stopped = true;
      break;
    }
  }
  starts_.clear ();
  return stopped;
}

bool
LeafPairTest::finishDeferred (double stop_probability, bool exhaustive, bool skip_dominated)
{
  if (starts_stopped_ || flushStarts (stop_probability, exhaustive))
    return true;
  std::stable_sort (deferred_.begin (), deferred_.end (),
                    [] (const Deferred& x, const Deferred& y) { return x.rho > y.rho; });
  for (const Deferred& d : deferred_)
  {
    if (skip_dominated && d.rho <= best_)
      break;  // sorted: every later pair is dominated too
    if (!fit (*d.a, *d.b, KernelMode::Ladder))
      continue;
    if (record (*d.a, *d.b, d.rho, !d.counted) > stop_probability && !exhaustive)
      return true;
  }
  return false;
}
} // namespace detail
} // namespace pcl_probcollision
