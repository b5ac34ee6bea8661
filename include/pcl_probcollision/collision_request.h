// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/classifier_params.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace pcl_probcollision
{
/** \brief How the traversal treats node pairs whose boxes are disjoint (METHOD.md 8.5). */
enum class TraversalMode
{
  /** \brief Deterministic (default): a disjoint pair multiplies the reach weight rho by
    * q = 1 - Pcov(a) Pcov(b) and is pruned once rho < rho_min; a leaf pair contributes
    * rho * P_leaf. */
  ExpectedWeight,
  /** \brief A disjoint pair is opened when u < q, u drawn from a generator seeded with `seed`:
    * the same inputs and seed give the same result. */
  Stochastic,
  /** \brief No leakage: boxes grown to expanded_k_sigma point standard deviations and only
    * overlapping pairs opened (the reference code's inflated boxes). Deterministic. */
  ExpandedBV
};

/** \brief What a collision query computes and how: only what a query needs (how each cloud is
  * modelled is in CloudModelParams, fixed when its CloudModel is built). Every member has a
  * documented default;
  * validate() throws pcl::BadArgumentException naming the first member out of range.
  *
  * Verdict thresholds are on the collision probability P (METHOD.md 7 states them on
  * 1 - P as A = 1 - free_below and B = 1 - collision_above): P < free_below is Free,
  * P > collision_above is InCollision, anything between is InContact.
  */
struct CollisionRequest
{
  /** \brief Below this P the pair is Free; (0, 0.5] (at 0 nothing would be Free). Default 0.1
    * (METHOD.md 7, A = 0.9). */
  double free_below = 0.1;
  /** \brief Above this P the pair is InCollision; [0.5, 1) (at 1 nothing would be), so
    * >= free_below. Default 0.9. */
  double collision_above = 0.9;
  /** \brief false (default): stop as soon as a leaf pair's contribution exceeds
    * collision_above (the verdict is then final and P a lower bound). true: visit every leaf
    * pair the traversal reaches, e.g. to get every point's probability. */
  bool exhaustive = false;
  /** \brief Fill per-point probabilities in the result (implies nothing about exhaustive). */
  bool per_point = false;
  /** \brief Fill the timings of the result. */
  bool enable_timings = false;

  /** \brief How the traversal treats node pairs whose boxes are disjoint (default
    * ExpectedWeight). */
  TraversalMode traversal = TraversalMode::ExpectedWeight;
  /** \brief ExpectedWeight: prune once the reach weight falls below this; [0, 1]. Default 1e-3. */
  double rho_min = 1e-3;
  /** \brief Seed of the Stochastic traversal. Default 1. */
  std::uint64_t seed = 1;
  /** \brief ExpandedBV: box growth in point standard deviations, >= 0. Default 3. */
  double expanded_k_sigma = 3.0;
  /** \brief Ladder classifier: fit every reached leaf pair's plane first and the kernel rungs
    * afterwards, largest reach weight first, only for pairs that can still raise P (ignored
    * with per_point). Same P when the query does not stop early; a query that does (P >
    * collision_above) may stop at a shallower pair before any kernel fit, so its P (a lower
    * bound either way) is lower. Faster on colliding poses; off by default because the lower
    * P of those poses costs ranking accuracy (docs/PERFORMANCE.md). */
  bool defer_kernel_fits = false;
  /** \brief A cap on the separators' work: at most this many leaf pairs tested per query
    * (CollisionResult::leaf_pairs_tested); 0 (default) = no cap. Leaf pairs are visited nearest
    * first (detail/bvh_traversal.h), so the pairs left over are the farther ones; a query that reaches the cap stops with P the
    * largest so far (CollisionResult::budget_exhausted, a lower bound; never Free, contact
    * under free_below). It bounds the worst
    * case at high noise, where inflated boxes overlap everywhere and thousands of pairs are
    * fitted (docs/PERFORMANCE.md, issue #17). Not used by the surface layer
    * (max_surface_pairs is its cap). */
  std::size_t max_leaf_fits = 0;
  /** \brief A cap on the surface layer's work (surface, surface_pooled, surface_ladder): it
    * stops before its next query leaf once this many leaf pairs have been tested (each query
    * leaf's pairs on each side count; a leaf's pairs are tested together, so the count may pass
    * the cap by one leaf's); 0 (default) = no cap. A capped answer is flagged
    * (CollisionResult::budget_exhausted): P is the largest so far, a lower bound (the verdict
    * never Free: contact under free_below), and the winding-number test of parts beyond reach is skipped. In the ladder the separators' answer
    * then stands where they read contact (a collision the capped rung found stands instead), and
    * the pool takes the lower bound where they read free. It bounds the surface layer's worst case, whose contact answers visit every leaf
    * pair within reach (docs/SURFACE.md, "A cap on the surface layer's work"): capped, only the
    * pairs the cap lets it reach are enumerated (docs/PERFORMANCE.md, "The surface layer's cap
    * bounds its enumeration too"). */
  std::size_t max_surface_pairs = 0;

  /** \brief The surface layer (METHOD.md 10a), experimental: instead of the separators, test
    * each object's points against the other's oriented surface (a local signed distance near
    * contact, a winding-number inside test when out of reach) and fill signed_distance. Needs
    * both models built with CloudModelParams::surface (ProbabilisticCollision builds them so when
    * its request asks); otherwise the separators answer, CollisionResult::answered_by says so and
    * CollisionResult::message says why.
    * Default off: on the evaluation's noisy piano-in-room clouds, whose normals are oriented by
    * propagation, it is not yet as accurate as the separators (docs/RESULTS.md, issue #16). */
  bool surface = false;
  /** \brief With surface on: also run the separators and answer the mean of the two
    * probabilities (a linear opinion pool), per point and for the pair; where the surface layer
    * finds one object wholly inside the other and the separators reach no leaf pair (their P = 0
    * says nothing there), its answer stands alone (answered_by SurfaceLayer). The two see different
    * things: the surface layer whether a point lies behind the other's surface, the separators
    * whether two sheets cross (thin parts, where noise leaves no inside). The signed distance
    * stays the surface layer's. Experimental, off by default; the rule was chosen on evaluation
    * runs with seeds other than the reported one (docs/SURFACE.md). validate() refuses it
    * without surface (it would change nothing: the separators would answer a request naming the
    * surface layer); pcd_collision's -surface_pooled sets both. */
  bool surface_pooled = false;
  /** \brief With surface on: a ladder, the separators first and the surface layer only where they
    * leave the answer open. The separators' answer stands where they reached no leaf pair (the
    * objects apart, unless two winding numbers find one wholly inside the other, where a surface
    * says where its inside is: then P = 1, the surface layer's) or found P above collision_above
    * (they see two sheets crossing, which the surface layer cannot where the noise is as thick
    * as the parts). Otherwise the surface
    * layer runs too, and answers alone where the separators' P lies in the contact band (they
    * cannot tell a touch from a part through a single scanned sheet: the README demo's 2 cm
    * penetration), or pooled with them as surface_pooled does where they answered free (between
    * sparse samples a part can pass unseen by the separators). Most free poses then cost the
    * separators alone. The rule was chosen on evaluation runs with seeds other than the reported
    * one (docs/SURFACE.md, "The ladder"); experimental, off by default. Excludes surface_pooled.
    * Like surface_pooled and surface_calibrated, refused by validate() without surface
    * (pcd_collision's -surface_ladder sets both). */
  bool surface_ladder = false;
  /** \brief With surface on: P (the surface layer's, or the pool's) goes through a calibration
    * map inside the default contact band [0.1, 0.9]: strictly increasing, onto the band, the
    * identity outside it, so rankings and the default thresholds' verdicts are kept. The maps
    * are fitted on procedural scenes the evaluation never reports (evaluate_collision
    * --fit-scene), where the raw P under-states collisions in the band, so they raise it; on the
    * reported piano-and-room scenes the raw P over-states them, and the maps make it worse
    * (docs/SURFACE.md, "Calibration"). No map fitted apart from those scenes helps them, so the
    * default is the model's raw P, P = Phi(-signed_distance / signed_distance_std). Per-point
    * values, signed_distance and its std are never mapped, nor is an answer resting on surface
    * the samples do not show (CollisionResult::unobserved: the maps were not fitted on those).
    * Refused by validate() without surface, as surface_pooled (pcd_collision's
    * -surface_calibrated needs -surface or a flag implying it). */
  bool surface_calibrated = false;
  /** \brief A distance at any separation, as FCL's distance request gives: beyond the reach of
    * the surface layer where it runs (alone, pooled or as the ladder's rung: no leaf pair within
    * its grown boxes, and neither object inside the other), else where the separators reached no
    * leaf pair (CollisionResult::no_leaf_tested), signed_distance is the distance between the
    * two clouds' nearest samples, and its std their covariances' along the line between them
    * with 0.29 of each one's spacing for where the surfaces pass between samples
    * (CollisionResult::sample_distance, nearest_point_a / nearest_point_b). Near contact the
    * surface layer's signed distance stands (NaN there without it: the separators give none;
    * where the ladder's separators find a sure collision, the surface layer runs for the
    * distance alone and their P stands), and it is an estimate, never a bound: the surface
    * layer does not stop at the first point that decides a collision but visits every pair
    * within reach, as with exhaustive (P is then not a lower bound either; about 3 times the
    * mean query near contact, docs/SURFACE.md).
    * An exact nearest-pair search over the two hierarchies; off by default, since a planner's
    * free poses would pay for it (docs/PERFORMANCE.md). */
  bool distance = false;
  /** \brief The separator fitted at each leaf pair (ClassifierParams' defaults). */
  ClassifierParams classifier;

  /** \brief Throws pcl::BadArgumentException naming the first member out of range (the
    * classifier's included), or surface_pooled, surface_ladder or surface_calibrated set
    * without surface, or surface_pooled with surface_ladder. collide() and collideBatch() run it
    * first (an InvalidInput result), ProbabilisticCollision::setRequest() too (it throws). */
  void validate () const;
  /** \brief The part of validate() that verdictFor() needs: free_below and collision_above. */
  void validateThresholds () const;
  /** \brief The thresholds' rule, its one owner: empty when free_below is in (0, 0.5] and
    * collision_above in [0.5, 1) (every verdict reachable), otherwise why not, naming the member
    * and its value. validateThresholds() throws it; pcd_collision's -thresholds prints it
    * (inline: the command line's parser links no library). */
  std::string
  thresholdsError () const
  {
    // P lies in [0, 1]: free_below = 0 would leave nothing free and collision_above = 1 nothing
    // in collision, so the ranges are open at those ends; each within its half also keeps the two
    // in order (contact then always holds P = 0.5) and names a NaN as out of range.
    char why[160] = "";
    if (!(free_below > 0.0 && free_below <= 0.5))
      std::snprintf (why, sizeof why, "free_below %g outside (0, 0.5] (P < free_below is free: every verdict must be reachable)",
                     free_below);
    else if (!(collision_above >= 0.5 && collision_above < 1.0))
      std::snprintf (why, sizeof why,
                     "collision_above %g outside [0.5, 1) (P > collision_above is collision: every verdict must be reachable)",
                     collision_above);
    return why;
  }
  /** \brief Every member equal (the classifier's parameters included). */
  bool operator== (const CollisionRequest& o) const;
  /** \brief The negation of operator==. */
  bool operator!= (const CollisionRequest& o) const { return !(*this == o); }
};
} // namespace pcl_probcollision
