// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/error_message.h>
#include <pcl_probcollision/detail/bvh_traversal.h>
#include <pcl_probcollision/detail/input_checks.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace pcl_probcollision
{
namespace
{
constexpr float kNotReached = std::numeric_limits<float>::quiet_NaN ();

void
fail (CollisionResult& result, CollisionResult::Status status, const std::string& message)
{
  result.status = status;
  result.message = message;
  result.verdict = Verdict::Unknown;
  result.probability = std::numeric_limits<double>::quiet_NaN ();
}

// Keeps the larger of a stored per-point value and a new one; NaN means "not reached yet".
void
keepMax (float& slot, double value)
{
  const float v = static_cast<float> (value);
  if (std::isnan (slot) || v > slot)
    slot = v;
}

/** \brief collide() on the two hierarchies, B mapped into A's local frame by T_a_b; the
  * request is valid and the pose rigid. Witness in A's local frame, per-point values in
  * hierarchy order. */
bool
collideLocal (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b,
              const CollisionRequest& request, CollisionResult& result, const RobustClassifier* classifier)
{
  if (a.empty () || b.empty ())
  {
    fail (result, CollisionResult::Status::InvalidInput,
          a.empty () ? "hierarchy A is empty (no finite point)" : "hierarchy B is empty (no finite point)");
    return false;
  }
  // The caller's classifier carries the random-feature draw; without one, draw it here.
  std::optional<RobustClassifier> own;
  if (!classifier)
    classifier = &own.emplace (request.classifier);

  result.points_a = a.size ();
  result.points_b = b.size ();
  if (request.per_point)
  {
    result.probabilities_a.assign (a.size (), kNotReached);
    result.probabilities_b.assign (b.size (), kNotReached);
  }

  std::vector<Eigen::Vector3d> means_a, means_b;
  std::vector<Eigen::Matrix3d> covs_a, covs_b;
  ClassifierResult leaf;
  double best = -1.0;
  std::string failure;
  std::size_t failures = 0;
  // Fits one leaf pair with the given kernel mode; false (failure noted) when it has no usable
  // separator.
  auto fit = [&] (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, KernelMode kernel) {
    const PointSetView view_a = a.gatherPoints (leaf_a, means_a, covs_a);
    const PointSetView view_b = b.gatherPoints (leaf_b, T_a_b, means_b, covs_b);
    if (classifier->classify (view_a, view_b, leaf, kernel))
      return true;
    if (failure.empty ())
      failure = leaf.message;
    ++failures;
    return false;
  };
  // Takes the fit in `leaf` into the result: counters, per-point values, maximum and witness.
  auto record = [&] (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho) {
    ++result.leaf_pairs_tested;
    result.classifier_iterations += static_cast<std::size_t> (leaf.iterations);
    result.kernel_leaf_pairs += leaf.rung == Rung::RFF || leaf.rung == Rung::RFFLarge ? 1 : 0;
    result.degenerate_leaf_pairs += leaf.degenerate ? 1 : 0;
    const auto span_a = a.indices (leaf_a);
    const auto span_b = b.indices (leaf_b);
    if (request.per_point)
    {
      for (std::size_t i = 0; i < span_a.size; ++i)
        keepMax (result.probabilities_a[span_a[i]], rho * leaf.probabilities_a[i]);
      for (std::size_t j = 0; j < span_b.size; ++j)
        keepMax (result.probabilities_b[span_b[j]], rho * leaf.probabilities_b[j]);
    }
    const double contribution = rho * leaf.probability;
    if (contribution > best)
    {
      best = contribution;
      const bool on_a = leaf.witness_side > 0;
      const int local = on_a ? span_a[leaf.witness_index] : span_b[leaf.witness_index];
      result.witness_side = on_a ? 1 : -1;
      result.witness_index = (on_a ? a : b).sourceIndex (local);
      result.witness_point = on_a ? means_a[leaf.witness_index] : means_b[leaf.witness_index];
      result.witness_normal = leaf.witness_normal;
    }
    return contribution;
  };

  // request.defer_kernel_fits: the Ladder's kernel rungs cost a hundred planes. The traversal
  // fits the plane of every leaf pair it reaches; a pair whose plane asks for a kernel rung
  // (RobustClassifier::needsKernel) is set aside, contributing nothing yet, and fitted in full
  // afterwards, largest reach weight first, unless the maximum by then makes it irrelevant.
  // Every pair fitted ends with the fit of a direct Ladder classify(), so without an early stop
  // the maximum is the same; with one (P > collision_above, a lower bound either way) the
  // traversal may stop at a shallower pair before any kernel fit, and P is a lower bound
  // below the default's.
  struct Deferred
  {
    const ProbabilisticBVH::Node* a;
    const ProbabilisticBVH::Node* b;
    double rho;
  };
  // Per-point values need every pair's final fit in traversal order: no deferral there.
  const bool lazy_kernel = request.defer_kernel_fits && !request.per_point &&
                           classifier->getParams ().kernel == KernelMode::Ladder;
  std::vector<Deferred> deferred;
  auto leaf_test = [&] (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho) {
    if (!fit (leaf_a, leaf_b, lazy_kernel ? KernelMode::Linear : classifier->getParams ().kernel))
      return std::numeric_limits<double>::quiet_NaN ();
    if (lazy_kernel && classifier->needsKernel (leaf))
    {
      deferred.push_back ({&leaf_a, &leaf_b, rho});
      return 0.0;
    }
    record (leaf_a, leaf_b, rho);
    return leaf.probability;
  };

  detail::TraversalParams params (request);
  // A pair whose reach weight is at most the maximum so far cannot raise it (its contribution
  // is rho * P_leaf <= rho): same probability and witness, fewer classifier fits. Per-point
  // values need every reachable leaf pair, so they keep the full traversal.
  params.skip_dominated = !request.per_point;
  detail::TraversalResult traversal;
  try
  {
    traversal = detail::traverseHierarchies (a, b, T_a_b, params, leaf_test);
  }
  catch (const pcl::PCLException& e)
  {
    fail (result, CollisionResult::Status::InvalidInput, errorMessage (e));
    return false;
  }
  bool stopped = traversal.lower_bound;
  if (!stopped && !deferred.empty ())
  {
    std::stable_sort (deferred.begin (), deferred.end (),
                      [] (const Deferred& x, const Deferred& y) { return x.rho > y.rho; });
    for (const Deferred& d : deferred)
    {
      if (params.skip_dominated && d.rho <= best)
        break;  // sorted: every later pair is dominated too
      if (!fit (*d.a, *d.b, KernelMode::Ladder))
        continue;
      if (record (*d.a, *d.b, d.rho) > params.stop_probability && !params.exhaustive)
      {
        stopped = true;
        break;
      }
    }
  }
  result.bv_tests = traversal.node_pairs_tested;
  if (failures > 0)
  {
    // A leaf pair without a usable separator would make the maximum a guess: report it.
    fail (result, CollisionResult::Status::NumericalFailure,
          "classifier failed on " + std::to_string (failures) + " leaf pair(s): " + failure);
    return false;
  }
  result.status = CollisionResult::Status::Ok;
  // The traversal's maximum counted set-aside pairs as 0; best holds every recorded pair.
  result.probability = std::max (traversal.probability, best);
  result.lower_bound = stopped;
  result.no_leaf_tested = traversal.no_leaf_tested;
  if (result.no_leaf_tested)
  {
    result.witness_side = 0;
    result.witness_index = -1;
  }
  result.verdict = verdictFor (result.probability, request);
  return true;
}
} // namespace

Verdict
verdictFor (double probability, const CollisionRequest& request)
{
  if (std::isnan (probability))
    return Verdict::Unknown;
  if (probability < request.free_below)
    return Verdict::Free;
  if (probability > request.collision_above)
    return Verdict::InCollision;
  return Verdict::InContact;
}


bool
collide (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
         CollisionResult& result, const RobustClassifier* classifier)
{
  const auto start = std::chrono::steady_clock::now ();
  result = CollisionResult ();
  try
  {
    request.validate ();
  }
  catch (const pcl::PCLException& e)
  {
    fail (result, CollisionResult::Status::InvalidInput, errorMessage (e));
    return false;
  }
  const std::string pose_error = detail::poseError (T_a_b, "T_a_b");
  if (!pose_error.empty ())
  {
    fail (result, CollisionResult::Status::InvalidInput, pose_error);
    return false;
  }
  // The hierarchies live in the models' local frames (x = local + origin): B's local points go
  // to A's local frame by T_local = Translate (-o_a) T_a_b Translate (o_b), composed in double.
  Eigen::Isometry3d T_local = T_a_b;
  T_local.translation () = (T_a_b.linear () * b.origin () + T_a_b.translation ()) - a.origin ();
  if (!collideLocal (a.hierarchy (), b.hierarchy (), T_local, request, result, classifier))
    return false;

  // Back to what the caller gave: the witness in A's frame, per-point values on the clouds.
  if (result.witness_side != 0)
    result.witness_point += a.origin ();
  if (request.per_point)
  {
    auto scatter = [] (std::vector<float>& values, const CloudModel& model) {
      std::vector<float> out (model.sourceSize (), kNotReached);
      const ProbabilisticBVH& bvh = model.hierarchy ();
      for (std::size_t j = 0; j < values.size (); ++j)
        out[static_cast<std::size_t> (bvh.sourceIndex (static_cast<int> (j)))] = values[j];
      values.swap (out);
    };
    scatter (result.probabilities_a, a);
    scatter (result.probabilities_b, b);
  }
  result.points_skipped_nonfinite = a.skippedPoints () + b.skippedPoints ();
  for (const CloudModel* m : {&a, &b})
    if (!m->warning ().empty ())
      result.message += (result.message.empty () ? "" : "; ") + m->warning ();
  if (request.enable_timings)
  {
    result.build_ms = 0.0;  // the models were built before
    result.query_ms = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
  }
  return true;
}
} // namespace pcl_probcollision
