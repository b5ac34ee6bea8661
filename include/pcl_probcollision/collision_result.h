// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace pcl_probcollision
{
/** \brief The three-way decision of METHOD.md 7. */
enum class Verdict
{
  Unknown,     ///< not computed (the query failed)
  Free,        ///< P < free_below
  InContact,   ///< free_below <= P <= collision_above: touching or too noisy to tell
  InCollision  ///< P > collision_above
};

/** \brief "free", "contact", "collision" or "unknown". */
const char* verdictName (Verdict verdict);

/** \brief Whose probability a result reports (CollisionRequest::surface, surface_pooled,
  * surface_ladder): with the ladder it differs from pose to pose. */
enum class AnsweredBy
{
  Unknown,       ///< not computed (the query failed)
  Separators,    ///< the leaf-pair classifiers of the paper (the default)
  SurfaceLayer,  ///< the surface layer alone (METHOD.md 10a)
  Pooled         ///< the mean of both (surface_pooled, or the ladder after a "free" fit)
};

/** \brief "separators", "surface", "pooled" or "unknown". */
const char* answeredByName (AnsweredBy answered_by);

/** \brief Outcome of a query. Anything not computed is NaN (numbers) or Unknown. */
struct CollisionResult
{
  /** \brief Whether the query answered; otherwise message says why. */
  enum class Status
  {
    Ok,
    InvalidInput,     ///< see message: no cloud, no finite point, non-finite pose, ...
    NumericalFailure  ///< see message: a classifier produced no usable separator
  };
  /** \brief Ok when the query answered, otherwise why not (InvalidInput until a query sets
    * it). */
  Status status = Status::InvalidInput;
  /** \brief Why the query failed; after a success empty, or the models' warnings (e.g. that
    * the separators answered a surface request), joined by "; ". */
  std::string message;

  /** \brief The verdict of P under the request's free_below and collision_above; Unknown
    * when the query failed. */
  Verdict verdict = Verdict::Unknown;
  /** \brief Whose answer P is. Separators also when CollisionRequest::surface is set but a model
    * carries no surface model (CloudModelParams::surface off): the request then falls back to the
    * paper's method, and this says so. */
  AnsweredBy answered_by = AnsweredBy::Unknown;
  /** \brief P(A, B) in [0, 1]: the largest reach-weighted leaf-pair probability. */
  double probability = std::numeric_limits<double>::quiet_NaN ();
  /** \brief Signed distance between the two surfaces in data units (METHOD.md 10a, the
    * surface layer): > 0 the gap, < 0 minus the penetration depth. NaN when not computed: the
    * surface layer is off (CollisionRequest::surface) or the query never came within reach of
    * both surfaces (no_leaf_tested without a far-field inside answer). The distance at the
    * query's most significant point (lowest d / std); when the query stopped early at a
    * collision (lower_bound), at the first point that decided it: the deepest may lie elsewhere
    * (CollisionRequest::exhaustive visits every pair; so does CollisionRequest::distance, whose
    * distance is never such a bound). Where the answer is a point deep inside the other object,
    * out of reach of its surface (or one object wholly inside the other, the ladder's
    * containment check), it is minus that point's distance to the other's nearest sample, in
    * every mode: the penetration is at least that deep (the point must cross the other's
    * surface to get out), and the translation that separates the two may be longer. */
  double signed_distance = std::numeric_limits<double>::quiet_NaN ();
  /** \brief Standard deviation of signed_distance (sensor noise of both clouds, the fitted
    * surfaces' own uncertainty and the discretisation between samples; where two thin sheets
    * cross, also half the crossing's depth bound, weighted by how sure the crossing is, as the
    * depth lies anywhere from 0 to that bound); NaN with it. */
  double signed_distance_std = std::numeric_limits<double>::quiet_NaN ();
  /** \brief True when signed_distance is the distance between the two clouds' nearest samples
    * (CollisionRequest::distance, the objects beyond the query's reach): a clearance between
    * samples, so between sparse samples a surface may pass up to about a spacing closer (it reads
    * long on average); its std is both samples' covariances along the line between them and, for
    * where each surface passes between its samples, 0.29 of each sample's spacing (its nearest
    * distinct neighbour in its hierarchy leaf). */
  bool sample_distance = false;
  /** \brief With sample_distance, the two nearest samples, A's (the input's for
    * ProbabilisticCollision) and B's, in the query frame (as witness_point); NaN otherwise. */
  Eigen::Vector3d nearest_point_a = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief B's nearest sample (see nearest_point_a). */
  Eigen::Vector3d nearest_point_b = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief True when the traversal stopped early: P is then a lower bound (the verdict is
    * InCollision and final, unless budget_exhausted, or pooled: CollisionRequest::surface_pooled
    * averages a stopped answer with the other's, which can read contact), and signed_distance is
    * the first deciding point's, not the deepest. */
  bool lower_bound = false;
  /** \brief True when the query stopped at CollisionRequest::max_leaf_fits with leaf pairs
    * left unfitted, or the surface layer at CollisionRequest::max_surface_pairs with leaf pairs
    * left untested: P (and lower_bound) is the largest over the pairs tested (the separators'
    * nearest first); the pairs left could only raise it. Such an answer never reads Free: under
    * free_below its verdict is InContact (undecided), its P still the bound; signed_distance is
    * then the tested leaves'. */
  bool budget_exhausted = false;
  /** \brief True when no leaf pair was tested (P = 0): every pair of boxes the traversal met was
    * disjoint, and its reach weight (METHOD.md 6.3) fell under CollisionRequest::rho_min (in
    * Stochastic mode: its draw failed). The objects may still lie within a few noise deviations
    * of each other: boxes of projected points are tight across their surface. For the surface
    * layer: no point came within reach of the other's surface (nor lies inside it), though leaf
    * boxes may have met (counted in bv_tests; leaf_pairs_tested is then 0). */
  bool no_leaf_tested = false;
  /** \brief True when the answer rests on surface the samples do not show (the surface layer
    * only; docs/SURFACE.md): the deciding point lies over a hole in the other cloud's samples
    * that the surface bridges (an occlusion shadow, wider than a sample spacing, with samples on
    * its far rim), or clearly behind (beyond its noise) a surface oriented by its viewpoint
    * (NormalOrientation::Viewpoint: a scan from one sensor, which never sees behind it). P and
    * the verdict then say what the bridged or occupied surface implies; a planner may treat
    * such a pose as unknown. Also where no point reads inside but a point within the scan's
    * bounding box or its hidden shell (SurfaceModel::hiddenShell), out of its samples' reach or
    * read outside by them, lies behind what the sensor saw along its line of sight
    * (SurfaceModel::behindView): the surface layer's P is
    * then at least 1/2 (at least 1/4
    * pooled with the separators': contact at the default thresholds), the distance 0 with a
    * standard deviation of that depth, and the witness normal points toward the sensor. */
  bool unobserved = false;
  /** \brief True when the answer is the full-resolution models' (CloudModel::fullResolution()):
    * a model merged its samples (CloudModelParams::noise_resolution), the merged answer was
    * the separators' contact at P >= 0.5, and the unmerged models, asked again with a budget of
    * 256 leaf-pair fits, found a collision. Every field is then theirs but the work counters
    * (bv_tests, leaf_pairs_tested and its parts, classifier_iterations), which count both
    * queries, whichever answer stands. */
  bool full_resolution = false;

  /** \brief The point attaining P: side +1 = input (A), -1 = target (B), 0 = none. */
  int witness_side = 0;
  /** \brief Its index in its own input cloud (-1 when none). */
  int witness_index = -1;
  /** \brief Its position and the separator's unit normal there (pointing toward A's side).
    * The position is the model's: with CloudModelParams::surface_projection (the default) the
    * sample moved onto its neighbours' plane, with CloudModelParams::noise_resolution the merged
    * point (the mean of the samples merged into it, witness_index one of them), not the stored
    * point (witness_index's). Both are
    * in the query frame: the frame the query's pose maps the other object into. That is
    * A's frame for collide (a, b, T_a_b, ...) and the target's (B's) for
    * ProbabilisticCollision::compute (T_target_input, ...); this is the one place the rule is
    * stated. The normal can be NaN even with a witness: the separator's gradient collapsed
    * there (coincident or exact points, a degenerate classifier;
    * ClassifierResult::witness_normal). The surface layer's is the other surface's outward
    * normal there, turned toward A's side; for a point found deep inside the other object (or
    * one object wholly inside the other), that of the other's sample nearest the point: the way
    * out (NaN where that sample has no normal). */
  Eigen::Vector3d witness_point = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief The unit normal at witness_point, toward A's side: the separator's or the
    * surface layer's (see witness_point, also for when it is NaN). */
  Eigen::Vector3d witness_normal = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());

  // Counters.
  std::size_t points_a = 0;                  ///< finite points of A used
  std::size_t points_b = 0;                  ///< finite points of B used
  std::size_t points_skipped_nonfinite = 0;  ///< NaN / Inf points skipped, both clouds
  std::size_t bv_tests = 0;                  ///< node pairs tested
  /** \brief Leaf pairs tested: fitted; passed over unfitted because their start plane could
    * not raise the maximum (RobustClassifier::classify's skip_at_or_below); or set aside by
    * their start plane to be fitted later, which a query that stops at a collision first
    * never fits. The surface layer's: the leaf pairs within its reach, 0 when no point came
    * within reach (no_leaf_tested). */
  std::size_t leaf_pairs_tested = 0;
  std::size_t kernel_leaf_pairs = 0;         ///< of which needed an RFF rung
  std::size_t degenerate_leaf_pairs = 0;     ///< of which had no separating direction
  std::size_t classifier_iterations = 0;     ///< solver iterations, all leaf pairs

  /** \brief Milliseconds; NaN unless request.enable_timings. build covers covariance
    * estimation and hierarchies (0 when they were reused), query the traversal. */
  double build_ms = std::numeric_limits<double>::quiet_NaN ();
  /** \brief Milliseconds of the traversal; NaN unless request.enable_timings. */
  double query_ms = std::numeric_limits<double>::quiet_NaN ();

  /** \brief Per-point P_i when request.per_point, index-aligned with each input cloud (its
    * full size, not its indices); the maximum over the leaf pairs a point took part in. NaN
    * for points that were not used (non-finite, outside the indices) or that no tested leaf
    * pair contained (the traversal never came near them). */
  std::vector<float> probabilities_a;
  /** \brief Per-point P_i of the target cloud (B), as probabilities_a. */
  std::vector<float> probabilities_b;

  /** \brief True when the query answered (status Ok). */
  bool ok () const { return status == Status::Ok; }
};

/** \brief Maps result's points and normal into another frame: witness_point and witness_normal
  * (with a witness), nearest_point_a and _b (with sample_distance), by T (the normal by its
  * rotation). collide (a, b, T_a_b) answers in A's frame; T = T_a_b.inverse () gives B's, as
  * ProbabilisticCollision::compute and pcd_collision report. The one place this is done, so that
  * every way of asking (C++, Python, Dask) gives the same bits. */
void mapResultPoints (CollisionResult& result, const Eigen::Isometry3d& T);
} // namespace pcl_probcollision
