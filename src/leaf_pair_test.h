// SPDX-License-Identifier: BSD-3-Clause
// The leaf-pair test of collide() (METHOD.md 6.3): one robust separator per pair of leaves the
// traversal reaches. Private to the library (src/), used by src/collide.cpp.
#pragma once

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/robust_classifier.h>
#include <pcl_probcollision/detail/start_plane.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <string>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Fits the robust separator to the union of two leaves (B's points mapped into A's
  * frame) and records each fit into a CollisionResult: counters, per-point values (request.
  * per_point), the running maximum and its witness (in A's frame, the hierarchies' frame).
  *
  * Passed to traverseHierarchies() as its leaf test. With request.defer_kernel_fits a pair
  * whose plane asks for a kernel rung is set aside (contributing nothing yet) and fitted in full by
  * finishDeferred(), largest reach weight first.
  *
  * With skip_dominated (no per-point values), each pair's start plane is first assessed from
  * the two hierarchies' own arrays, without gathering the points (detail/start_plane.h). A pair it
  * shows dominated is passed over; a pair it shows far from reaching is set aside and fitted
  * later, largest start first (flushStarts()), so that the maximum rises early and more pairs
  * are passed over, and a collision stops before the pairs that cannot decide it are fitted.
  */
class LeafPairTest
{
public:
  /** \brief result's per-point arrays are sized here when request.per_point. With
    * skip_dominated (the traversal's), a pair whose start plane stays a normal quantile under
    * what it would have to reach is not fitted (RobustClassifier::classify's skip_at_or_below;
    * kStartPlaneMargin). */
  LeafPairTest (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b,
                const CollisionRequest& request, const RobustClassifier& classifier, CollisionResult& result,
                bool skip_dominated);

  /** \brief The traversal's leaf test: P_leaf of the two leaves (for a pair passed over, its
    * start plane's maximum, which stays under the maximum so far), NaN when the classifier has
    * no usable separator (counted in failures()). For a pair set aside (its kernel rungs with
    * defer_kernel_fits, or the whole pair by its start plane) it returns the largest fitted
    * contribution so far over rho, rounded down: a lower bound of the final maximum for the
    * traversal's pruning. */
  double operator() (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho);

  /** \brief Fits the pairs set aside: those set aside by their start plane first (largest
    * start z first, flushStarts()), then those whose kernel rungs were deferred, largest reach
    * weight first, skipping those that cannot raise the maximum when skip_dominated; true when a contribution exceeded stop_probability
    * and exhaustive is off (the maximum is then a lower bound). */
  bool finishDeferred (double stop_probability, bool exhaustive, bool skip_dominated);

  /** \brief The largest recorded contribution rho * P_leaf (-1 before any). */
  double best () const { return best_; }
  /** \brief Leaf pairs without a usable separator, and the first one's message. */
  std::size_t failures () const { return failures_; }
  const std::string& firstFailure () const { return failure_; }

private:
  /** \brief The start-plane bound of a pair of reach weight rho (RobustClassifier::classify's
    * skip_at_or_below; -1 when none applies). */
  double skipBelow (double rho);
  /** \brief Fits the pairs set aside by their start planes, largest start z first; true when a
    * contribution exceeded stop_probability and exhaustive is off. */
  bool flushStarts (double stop_probability, bool exhaustive);

  /** \brief Fits one pair with the given kernel mode into leaf_ (not when its start plane's
    * maximum is at most skip_at_or_below: leaf_.dominated); false (failure noted) when it has
    * no usable separator. */
  bool fit (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, KernelMode kernel,
            double skip_at_or_below = -1.0);
  /** \brief Takes the fit in leaf_ into the result (counted as a tested pair unless it was
    * counted when set aside); returns its contribution rho * P_leaf. */
  double record (const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH::Node& leaf_b, double rho,
                 bool count = true);

  struct Deferred
  {
    const ProbabilisticBVH::Node* a;
    const ProbabilisticBVH::Node* b;
    double rho;
    double start_z;        ///< the start plane's largest z_i (detail::startPlaneZ())
    bool counted = false;  ///< counted as tested when set aside (by its start plane)
  };

  const ProbabilisticBVH& a_;
  const ProbabilisticBVH& b_;
  const Eigen::Isometry3d& T_a_b_;
  const CollisionRequest& request_;
  const RobustClassifier& classifier_;
  CollisionResult& result_;
  bool skip_dominated_;
  /** \brief The last best_ / rho seen and the start-plane bound it gives. */
  double skip_bound_ = -1.0, skip_below_ = -1.0;
  /** \brief Kernel rungs deferred (defer_kernel_fits; never with per-point values, which need
    * every pair's final fit in traversal order). */
  bool lazy_kernel_ = false;

  std::vector<Eigen::Vector3d> means_a_, means_b_;
  std::vector<Eigen::Matrix3d> covs_a_, covs_b_;
  ClassifierResult leaf_;
  double best_ = -1.0;
  std::string failure_;
  std::size_t failures_ = 0;
  std::vector<Deferred> deferred_;
  /** \brief Start planes assessed before any gather (skip_dominated, not RFF, squared hinge). */
  bool assess_starts_ = false;
  double C_ = 0.0;  ///< the classifier's C, for detail::passesOver()
  /** \brief Pairs set aside by their start planes, and whether a flush of them stopped. */
  std::vector<Deferred> starts_;
  bool starts_stopped_ = false;
};
} // namespace detail
} // namespace pcl_probcollision
