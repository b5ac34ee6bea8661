// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/error_message.h>
#include <pcl_probcollision/detail/bvh_traversal.h>
#include <pcl_probcollision/detail/input_checks.h>

#include "leaf_pair_test.h"
#include "nearest_samples.h"
#include "surface_calibration.h"
#include "surface_test.h"

#include <pcl/exceptions.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
namespace
{
constexpr float kNotReached = std::numeric_limits<float>::quiet_NaN ();
/** \brief A merged model's contact answer at or above this P is asked again at full resolution
  * (CloudModelParams::keep_full_resolution): the merged points' broad covariances read some
  * deep collisions as contact (P 0.64-0.89 on the evaluation). Below it the answer leans to
  * free, where the full resolution's over-confident collisions would mostly cost calibration
  * (docs/PERFORMANCE.md, "A full-resolution rung for merged clouds"). */
constexpr double kFullResolutionFrom = 0.5;
/** \brief Leaf-pair fits the full-resolution query may make: a bound on its worst case (the
  * unmerged query's worst at 4 % noise: 73 ms on the evaluation's development seeds). 512 gave
  * the same easy answers there, 128 lost one, 1,024 gained one at a worse Brier in every cell.
  * Exhausted without a collision, the merged answer stands. */
constexpr std::size_t kFullResolutionFits = 256;

void
fail (CollisionResult& result, CollisionResult::Status status, const std::string& message)
{
  result.status = status;
  result.message = message;
  result.verdict = Verdict::Unknown;
  result.probability = std::numeric_limits<double>::quiet_NaN ();
}

/** \brief collide() on the two hierarchies, B mapped into A's local frame by T_a_b; the
  * request is valid and the pose rigid. Traversal (detail/bvh_traversal.h) with the leaf-pair
  * test (leaf_pair_test.h). Witness in A's local frame, per-point values in hierarchy order. */
bool
collideLocal (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b,
              const CollisionRequest& request, CollisionResult& result, const RobustClassifier* classifier)
{
  // Neither hierarchy is empty: a CloudModel always holds at least one point.
  // The caller's classifier carries the random-feature draw; without one, each thread keeps
  // the last one it drew: the draw (1024 features) costs tens of microseconds, more than a
  // whole query far from contact. Same parameters, same seed, same draw.
  thread_local std::optional<RobustClassifier> cached;
  if (!classifier)
  {
    if (!cached || cached->getParams () != request.classifier)
      cached.emplace (request.classifier);
    classifier = &*cached;
  }

  result.points_a = a.size ();
  result.points_b = b.size ();
  detail::TraversalParams params (request);
  // A pair whose reach weight is at most the maximum so far cannot raise it (its contribution
  // is rho * P_leaf <= rho): same probability and witness, fewer classifier fits. The leaf test
  // also passes over a pair whose start plane stays a normal quantile under what the pair would
  // have to reach (kStartPlaneMargin): a fit almost never rises that far above its start, so
  // answers move only in rare cases, by little (docs/PERFORMANCE.md, "Pairs passed over by their
  // start plane"). Per-point values need every reachable leaf pair's fit, so they keep the full
  // traversal.
  params.skip_dominated = !request.per_point;
  detail::LeafPairTest leaf_test (a, b, T_a_b, request, *classifier, result, params.skip_dominated);
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
  // A capped traversal still finishes the pairs it set aside (their kernel fits; the pairs were
  // counted against the cap when their planes were fitted).
  bool stopped = traversal.lower_bound && !traversal.budget_exhausted;
  if (!stopped)
    stopped = leaf_test.finishDeferred (params.stop_probability, params.exhaustive, params.skip_dominated);
  stopped = stopped || traversal.budget_exhausted;
  result.budget_exhausted = traversal.budget_exhausted;
  result.bv_tests = traversal.node_pairs_tested;
  if (leaf_test.failures () > 0)
  {
    // A leaf pair without a usable separator would make the maximum a guess: report it.
    fail (result, CollisionResult::Status::NumericalFailure,
          "classifier failed on " + std::to_string (leaf_test.failures ()) + " leaf pair(s): " +
              leaf_test.firstFailure ());
    return false;
  }
  result.status = CollisionResult::Status::Ok;
  // The traversal's maximum counted set-aside pairs as 0; best holds every recorded pair.
  result.probability = std::max (traversal.probability, leaf_test.best ());
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
/** \brief The surface layer (request.surface): each object's points against the other's
  * oriented surface (surface_test.h). Witness in A's local frame, per-point values in hierarchy
  * order. */
bool
collideSurface (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b,
                const CollisionRequest& request, CollisionResult& result, bool containment_only = false,
                detail::SurfaceAnswer* answer = nullptr)
{
  result.points_a = a.size ();
  result.points_b = b.size ();
  if (request.per_point)
  {
    result.probabilities_a.assign (a.size (), kNotReached);
    result.probabilities_b.assign (b.size (), kNotReached);
  }
  detail::SurfaceAnswer s;
  try
  {
    s = containment_only ? detail::containmentTest (a, b, T_a_b, request, request.per_point ? &result.probabilities_a : nullptr,
                                                    request.per_point ? &result.probabilities_b : nullptr)
                         : detail::surfaceTest (a, b, T_a_b, request, request.per_point ? &result.probabilities_a : nullptr,
                                                request.per_point ? &result.probabilities_b : nullptr);
  }
  catch (const pcl::PCLException& e)
  {
    fail (result, CollisionResult::Status::InvalidInput, errorMessage (e));
    return false;
  }
  if (answer)
    *answer = s;
  result.status = CollisionResult::Status::Ok;
  result.probability = s.probability;
  result.signed_distance = s.signed_distance;
  result.signed_distance_std = s.signed_distance_std;
  result.unobserved = s.unobserved;
  result.no_leaf_tested = !s.reached;
  result.lower_bound = s.stopped_early || s.budget_exhausted;
  result.budget_exhausted = s.budget_exhausted;
  // Leaf pairs whose boxes met within reach but whose points all lay beyond it tested nothing:
  // with no_leaf_tested they count as node tests alone (bv_tests), as the ladder counts a
  // surface layer that reached nothing. Counted, they read "leaf pairs 1" beside "no leaf pair
  // tested" (found by a probe).
  result.leaf_pairs_tested = s.reached ? s.leaf_pairs : 0;
  result.bv_tests = s.bv_tests;
  result.witness_side = s.witness_side;
  if (s.witness_side != 0)
  {
    result.witness_index = (s.witness_side > 0 ? a : b).hierarchy ().sourceIndex (s.witness_index);
    result.witness_point = s.witness_point;
    result.witness_normal = s.witness_normal;
  }
  result.verdict = verdictFor (result.probability, request);
  return true;
}
/** \brief The separators' share of a combined answer: their work counted in into, their
  * witness where the surface layer has none. */
void
addSeparators (CollisionResult& into, const CollisionResult& separators)
{
  into.budget_exhausted = into.budget_exhausted || separators.budget_exhausted;
  into.no_leaf_tested = into.no_leaf_tested && separators.no_leaf_tested;
  if (into.witness_side == 0 && separators.witness_side != 0)
  {
    into.witness_side = separators.witness_side;
    into.witness_index = separators.witness_index;
    into.witness_point = separators.witness_point;
    into.witness_normal = separators.witness_normal;
  }
  into.bv_tests += separators.bv_tests;
  into.leaf_pairs_tested += separators.leaf_pairs_tested;
  into.kernel_leaf_pairs = separators.kernel_leaf_pairs;
  into.degenerate_leaf_pairs = separators.degenerate_leaf_pairs;
  into.classifier_iterations = separators.classifier_iterations;
}
/** \brief The separators' answer stands in place of a surface layer's that said nothing usable:
  * its work counted in; flagged capped where max_surface_pairs cut it short (the leaves left
  * might have said something, so P is then a lower bound). */
void
separatorsStand (CollisionResult& result, CollisionResult&& separators, bool capped)
{
  separators.bv_tests += result.bv_tests;
  separators.leaf_pairs_tested += result.leaf_pairs_tested;
  result = std::move (separators);
  result.budget_exhausted = result.budget_exhausted || capped;
  result.lower_bound = result.lower_bound || capped;
}

/** \brief The surface layer's answer (into) pooled with the separators' on the same pair
  * (CollisionRequest::surface_pooled): the mean of the two probabilities, per point where both
  * reached it (else the one that did); the surface layer's distance and witness (the
  * separators' when the surface layer reached nothing); the work of both counted. A point
  * inside the other object by the winding number (SurfaceAnswer::inside_confirmed: deep inside,
  * or one object wholly inside the other) is what the separators cannot see, since no two
  * surfaces need cross there: their P then says nothing, and the surface layer's stands alone (a
  * ball inside a box near its wall read contact 0.5): returns false then. */
bool
pool (CollisionResult& into, const CollisionResult& separators, const CollisionRequest& request, bool inside_confirmed)
{
  const bool pooled = !inside_confirmed;
  if (pooled)
    into.probability = 0.5 * (into.probability + separators.probability);
  if (pooled)
    into.lower_bound = into.lower_bound || separators.lower_bound;
  addSeparators (into, separators);
  auto mean = [] (std::vector<float>& values, const std::vector<float>& other) {
    for (std::size_t i = 0; i < values.size () && i < other.size (); ++i)
      values[i] = std::isnan (values[i]) ? other[i] : std::isnan (other[i]) ? values[i] : 0.5f * (values[i] + other[i]);
  };
  if (pooled)
  {
    mean (into.probabilities_a, separators.probabilities_a);
    mean (into.probabilities_b, separators.probabilities_b);
  }
  into.verdict = verdictFor (into.probability, request);
  return pooled;
}
/** \brief CollisionRequest::distance beyond reach: the nearest samples' distance and its std,
  * the points in the query frame. */
void
sampleDistance (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_local, CollisionResult& result)
{
  const detail::NearestSamples n = detail::nearestSamples (a.hierarchy (), b.hierarchy (), T_local);
  if (n.index_a < 0)
    return;
  const Eigen::Vector3d d = n.point_a - n.point_b;
  const double length = d.norm ();
  const PackedCovariance& cov_a = a.hierarchy ().covariances ()[static_cast<std::size_t> (n.index_a)];
  const PackedCovariance& cov_b = b.hierarchy ().covariances ()[static_cast<std::size_t> (n.index_b)];
  double variance;
  if (length > 0.0)
  {
    const Eigen::Vector3d u = d / length;
    variance = cov_a.quadratic (u) + cov_b.quadratic (T_local.linear ().transpose () * u);
  }
  else  // coincident samples: no direction, so the mean over directions (a third of the traces)
    variance = (double (cov_a.xx) + cov_a.yy + cov_a.zz + cov_b.xx + cov_b.yy + cov_b.zz) / 3.0;
  // Where each surface passes between its samples: the discretisation term of the surface layer,
  // 0.29 of the local spacing a side. Without it, +-2 std covered the exact (mesh) distance in
  // 78 % of bench_performance's poses beyond reach (the samples' distance reads long by a median
  // of 5 mm, 0.4 sigma_eff); with it 96 % (BM_Distance).
  variance += std::pow (detail::kDiscretisationPerDistance * n.spacing_a, 2) +
              std::pow (detail::kDiscretisationPerDistance * n.spacing_b, 2);
  result.signed_distance = length;
  result.signed_distance_std = std::sqrt (std::max (variance, 0.0));
  result.sample_distance = true;
  result.nearest_point_a = n.point_a + a.origin ();
  result.nearest_point_b = n.point_b + a.origin ();
  result.bv_tests += n.node_pairs;
}
} // namespace

Verdict
verdictFor (double probability, const CollisionRequest& request)
{
  request.validateThresholds ();
  if (std::isnan (probability))
    return Verdict::Unknown;
  // Not a probability: a caller's bug, never a verdict (1.5 read collision, -0.1 free).
  if (!(probability >= 0.0 && probability <= 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::verdictFor] probability " << probability << " outside [0, 1]");
  if (probability < request.free_below)
    return Verdict::Free;
  if (probability > request.collision_above)
    return Verdict::InCollision;
  return Verdict::InContact;
}


namespace
{
/** \brief collide() on the two models as they are, without the full-resolution rung and the
  * timing. */
bool
collideModels (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b_given,
               const CollisionRequest& request, CollisionResult& result, const RobustClassifier* classifier)
{
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
  // A classifier carries its parameters (and its random-feature draw): one built with others
  // would answer for them, not for the request (found in review: P 0.39 became 1).
  if (classifier && classifier->getParams () != request.classifier)
  {
    fail (result, CollisionResult::Status::InvalidInput,
          "the classifier given was built with parameters other than request.classifier's");
    return false;
  }
  const std::string pose_error = detail::poseError (T_a_b_given, "T_a_b");
  if (!pose_error.empty ())
  {
    fail (result, CollisionResult::Status::InvalidInput, pose_error);
    return false;
  }
  // A rotation given with rounded digits, taken to the nearest rotation (or as given when exact).
  const Eigen::Isometry3d T_a_b = detail::rigidPose (T_a_b_given);
  // The hierarchies live in the models' local frames (x = local + origin): B's local points go
  // to A's local frame by T_local = Translate (-o_a) T_a_b Translate (o_b), composed in double.
  Eigen::Isometry3d T_local = T_a_b;
  T_local.translation () = (T_a_b.linear () * b.origin () + T_a_b.translation ()) - a.origin ();
  // The surface layer answers when both models carry a surface; otherwise (or with
  // request.surface off) the separators do, as in the paper.
  const bool surface = request.surface && !a.surface ().empty () && !b.surface ().empty ();
  // Whose answer stands: the surface layer's (alone or pooled) or the separators'.
  bool from_surface = surface, pooled = surface && request.surface_pooled;
  // Whether the surface layer reached a leaf pair (its reach is spatial: boxes grown by the noise
  // and a spacing), for a distance asked beyond it; the separators' weighted traversal can fit a
  // pair of disjoint boxes at any separation, so their no_leaf_tested does not say "far".
  bool surface_ran = false, surface_reached = false;
  // Whether one of the answers pooled or standing ran in full (no cap reached) and read free:
  // a cap on the other cannot make a free answer undecided (below, budget_exhausted).
  bool free_in_full = false;
  const auto freeInFull = [&request] (const CollisionResult& r, bool capped, bool reached) {
    return !capped && reached && r.probability < request.free_below;
  };
  if (surface && request.surface_ladder)
  {
    // The ladder (CollisionRequest::surface_ladder): the separators first; the surface layer
    // where they reached a leaf pair and found no sure collision.
    CollisionResult separators;
    if (!collideLocal (a.hierarchy (), b.hierarchy (), T_local, request, separators, classifier))
    {
      result = separators;
      return false;
    }
    from_surface = !separators.no_leaf_tested && !(separators.probability > request.collision_above);
    if (from_surface)
    {
      detail::SurfaceAnswer answer;
      if (!collideSurface (a, b, T_local, request, result, false, &answer))
        return false;
      surface_ran = true;
      surface_reached = !result.no_leaf_tested;
      free_in_full = freeInFull (separators, separators.budget_exhausted, true) ||
                     freeInFull (result, answer.budget_exhausted, surface_reached);
      pooled = separators.probability < request.free_below;
      if (answer.budget_exhausted && !pooled && !(result.probability > request.collision_above))
      {
        // Capped in the separators' contact band (max_surface_pairs) short of a collision: the
        // leaves it saw are no ground to move their contact toward free; theirs stands. A
        // collision it found stands (a lower bound past the threshold: only an exhaustive or
        // per-point query, or an asked distance, goes on past one).
        separatorsStand (result, std::move (separators), true);
        from_surface = false;
      }
      else if (!surface_reached)
      {
        // No point within the surface layer's reach: it has nothing to say, and its P = 0 would
        // turn the separators' contact into "free" (two coincident clouds of two points read free).
        separatorsStand (result, std::move (separators), answer.budget_exhausted);
        from_surface = pooled = false;
      }
      else if (pooled)
        pooled = pool (result, separators, request, answer.inside_confirmed);
      else
        addSeparators (result, separators);
    }
    else if (separators.no_leaf_tested)
    {
      // Nothing within the separators' reach: one object may still lie wholly inside the other,
      // which two winding numbers tell (where a surface says where its inside is).
      if (!collideSurface (a, b, T_local, request, result, true))
        return false;
      from_surface = !result.no_leaf_tested;
      if (from_surface)
        addSeparators (result, separators);
      else
        result = std::move (separators);
    }
    else
    {
      result = std::move (separators);
      // A sure collision of the separators carries no distance. Asked for one, the caller gets
      // the surface layer's, as it gives alone; P, the verdict and the witness stay theirs.
      if (request.distance)
      {
        CollisionRequest for_distance = request;
        for_distance.per_point = false;
        CollisionResult surface_answer;
        if (!collideSurface (a, b, T_local, for_distance, surface_answer))
        {
          result = std::move (surface_answer);
          return false;
        }
        surface_ran = true;
        surface_reached = !surface_answer.no_leaf_tested;
        result.signed_distance = surface_answer.signed_distance;
        result.signed_distance_std = surface_answer.signed_distance_std;
        result.bv_tests += surface_answer.bv_tests;
        result.leaf_pairs_tested += surface_answer.leaf_pairs_tested;
        // A capped surface layer's distance is its leaves' so far, a bound.
        result.budget_exhausted = result.budget_exhausted || surface_answer.budget_exhausted;
      }
    }
  }
  else
  {
    detail::SurfaceAnswer answer;
    if (surface ? !collideSurface (a, b, T_local, request, result, false, &answer)
                : !collideLocal (a.hierarchy (), b.hierarchy (), T_local, request, result, classifier))
      return false;
    surface_ran = surface;
    surface_reached = surface && !result.no_leaf_tested;
    // Reaching no point, the surface layer may still have met leaves whose samples carry no
    // normal (a cloud of coincident, collinear or a few points has no surface): it cannot judge
    // them, and its P = 0 would read "free" (coincident clouds of 1-100 points did). The
    // separators answer then, as in the ladder.
    const bool defer = surface && !surface_reached && answer.unjudged;
    if (pooled || defer)
    {
      CollisionResult separators;
      if (!collideLocal (a.hierarchy (), b.hierarchy (), T_local, request, separators, classifier))
      {
        result = separators;
        return false;
      }
      free_in_full = freeInFull (separators, separators.budget_exhausted, true) ||
                     (!defer && freeInFull (result, answer.budget_exhausted, surface_reached));
      if (defer)
      {
        separatorsStand (result, std::move (separators), result.budget_exhausted);
        from_surface = pooled = false;
      }
      else
        pooled = pool (result, separators, request, answer.inside_confirmed);
    }
  }
  result.answered_by = !from_surface ? AnsweredBy::Separators : pooled ? AnsweredBy::Pooled : AnsweredBy::SurfaceLayer;
  // The maps were fitted on answers the samples show; an unobserved one (the shadow rule's
  // unknown 1/2, a bridged hole) is not what they describe, and keeps its P.
  if (from_surface && request.surface_calibrated && !result.unobserved)
  {
    result.probability = detail::calibratedSurfaceProbability (
        result.probability, pooled ? detail::SurfaceCalibration::Pooled : detail::SurfaceCalibration::SurfaceLayer);
    result.verdict = verdictFor (result.probability, request);
  }

  // Beyond reach, a distance when asked (CollisionRequest::distance): beyond the surface layer's
  // reach where it ran in full, else where the separators reached no leaf pair.
  // The separators' weighted traversal fits a pair of disjoint boxes at any separation (two
  // clouds of a leaf each always do): a "free" answer of theirs is beyond reach where no leaf
  // pair is within the surface layer's reach (clouds of under about 20 points never got a
  // distance).
  const bool beyond_reach =
      surface_ran ? !surface_reached
                  : result.no_leaf_tested ||
                        (request.distance && result.verdict == Verdict::Free &&
                         !detail::withinReach (a.hierarchy (), b.hierarchy (), T_local,
                                               std::fmax (a.medianNeighbourSpacing (), b.medianNeighbourSpacing ())));
  if (request.distance && beyond_reach && std::isnan (result.signed_distance))
    sampleDistance (a, b, T_local, result);
  // Back to what the caller gave: the witness in A's frame, per-point values on the clouds.
  if (result.witness_side != 0)
  {
    result.witness_point += a.origin ();
    result.witness_index = (result.witness_side > 0 ? a : b).sourceIndex (result.witness_index);
  }
  if (request.per_point)
  {
    auto scatter = [] (std::vector<float>& values, const CloudModel& model) {
      std::vector<float> out (model.sourceSize (), kNotReached);
      const ProbabilisticBVH& bvh = model.hierarchy ();
      const std::vector<int>& point_of = model.pointOfSource ();
      if (!point_of.empty ())  // merged samples: each one reports its merged point's value
      {
        for (std::size_t i = 0; i < out.size (); ++i)
          if (point_of[i] >= 0 && static_cast<std::size_t> (point_of[i]) < values.size ())
            out[i] = values[static_cast<std::size_t> (point_of[i])];
      }
      else
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
  // A query cut short by a cap (max_leaf_fits, max_surface_pairs) did not look everywhere: its P
  // is a lower bound, and "free" a claim it cannot make (a gripper 2 cm into a table read free
  // P >= 0 with max_surface_pairs 1). It reads contact, undecided; P stays the bound. Where one
  // of two answers pooled or standing ran in full and read free (the ladder's separators, when
  // its capped surface rung found nothing more), free stands, as that answer alone gives it.
  if (result.budget_exhausted && result.verdict == Verdict::Free && !free_in_full)
    result.verdict = Verdict::InContact;
  // The surface layer asked for where a model has none: the separators answered (answered_by),
  // and the message says why, as a model's warning does.
  if (request.surface && !surface)
    result.message += std::string (result.message.empty () ? "" : "; ") + "request.surface: model " +
                      (a.surface ().empty () ? "a" : "b") +
                      " was built without a surface model (CloudModelParams::surface), so the separators answered";
  return true;
}
} // namespace

bool
collide (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
         CollisionResult& result, const RobustClassifier* classifier)
{
  const auto start = std::chrono::steady_clock::now ();
  if (!collideModels (a, b, T_a_b, request, result, classifier))
    return false;
  // The full-resolution rung (CloudModelParams::keep_full_resolution): the separators' contact
  // on a merged model, leaning to collision, asked again unmerged within a budget; its collision
  // stands. Only the separators' answers: the budget bounds their work, not the surface layer's.
  const CloudModel* full_a = a.fullResolution ();
  const CloudModel* full_b = b.fullResolution ();
  if ((full_a || full_b) && result.answered_by == AnsweredBy::Separators && result.verdict == Verdict::InContact &&
      result.probability >= kFullResolutionFrom)
  {
    CollisionRequest full_request = request;
    full_request.max_leaf_fits =
        request.max_leaf_fits > 0 ? std::min (request.max_leaf_fits, kFullResolutionFits) : kFullResolutionFits;
    CollisionResult full;
    if (!collideModels (full_a ? *full_a : a, full_b ? *full_b : b, T_a_b, full_request, full, classifier))
    {
      result = std::move (full);
      return false;
    }
    // The answer that stands counts the work of both queries.
    const bool full_stands = full.verdict == Verdict::InCollision;
    CollisionResult& kept = full_stands ? full : result;
    const CollisionResult& other = full_stands ? result : full;
    kept.bv_tests += other.bv_tests;
    kept.leaf_pairs_tested += other.leaf_pairs_tested;
    kept.kernel_leaf_pairs += other.kernel_leaf_pairs;
    kept.degenerate_leaf_pairs += other.degenerate_leaf_pairs;
    kept.classifier_iterations += other.classifier_iterations;
    if (full_stands)
    {
      full.full_resolution = true;
      result = std::move (full);
    }
  }
  if (request.enable_timings)
  {
    result.build_ms = 0.0;  // the models were built before
    result.query_ms = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
  }
  return true;
}
} // namespace pcl_probcollision
