// SPDX-License-Identifier: BSD-3-Clause
// collide(), collideBatch() and verdictFor() (collision.h): the query on two CloudModel, one
// pose at a time or many on several threads. Most models are built from UncertainCloud directly
// (scenes.h: no FLANN, no OpenMP), so that ThreadSanitizer sees only our code; every model is
// built before any thread starts. Tests named *Concurrent* run under ThreadSanitizer in CI
// (scripts/ci-reliability.sh). verdictFor() has its boundary table at the end, and is checked on
// every answer by expectSane().
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "result_checks.h"
#include "sanitized_build.h"
#include "scenes.h"
#include "seeded_draws.h"

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace pcl_probcollision;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::expectSameResult;
using pcl_probcollision_test::expectSane;
using pcl_probcollision_test::jitteredGrid;
using pcl_probcollision_test::organizedPatch;
using pcl_probcollision_test::patchWithHole;
using pcl_probcollision_test::poseSweep;
using pcl_probcollision_test::randomAxisAnglePose;
using pcl_probcollision_test::randomSheet;
using pcl_probcollision_test::Shape;
using pcl_probcollision_test::shapeCloud;
using pcl_probcollision_test::shapeName;
using pcl_probcollision_test::verdictCounts;

namespace
{
// Sanitized builds (CI's ASan and TSan steps) run smaller workloads of the same tests: the
// contracts are the same, instrumented code is 10-50x slower.
#ifdef PCL_PC_SANITIZED
constexpr int kConcurrentPoses = 8;  // still one per thread
constexpr int kPoses = 9;            // still three poses per thread
#else
constexpr int kConcurrentPoses = 48;
constexpr int kPoses = 30;
#endif

/** \brief Two organized patches, 0.1 and 0.2 m across at z = 0, with 2 mm of isotropic noise. */
void
setPatches (ProbabilisticCollision<pcl::PointXYZ>& pc)
{
  pc.setInputCloud (organizedPatch (0.1, 0.01, 0.0, 0.001, 12));
  pc.setTargetCloud (organizedPatch (0.2, 0.01, 0.0, 0.001, 13));
  pc.setInputNoise (SensorNoiseModel::isotropic (0.002));
  pc.setTargetNoise (SensorNoiseModel::isotropic (0.002));
}
} // namespace

// ---------------------------------------------------------------------------------------------
// collide()

TEST (Collide, ConcurrentCollideOnSharedHierarchiesMatchesSerial)
{
  ProbabilisticCollision<pcl::PointXYZ> pc;
  setPatches (pc);
  CollisionResult warmup;
  ASSERT_TRUE (pc.compute (warmup));
  const auto a = pc.getInputModel ();
  const auto b = pc.getTargetModel ();
  CollisionRequest request;
  request.exhaustive = true;
  const RobustClassifier classifier (request.classifier);
  std::mt19937 rng (14);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 16; ++i)
    poses.push_back (randomAxisAnglePose (rng, 0.03));
  std::vector<double> serial (poses.size ()), parallel (poses.size (), -1.0);
  for (std::size_t i = 0; i < poses.size (); ++i)
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*a, *b, poses[i], request, r, &classifier));
    serial[i] = r.probability;
  }
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back ([&, t] () {
      for (std::size_t i = t; i < poses.size (); i += 4)
      {
        CollisionResult r;
        if (collide (*a, *b, poses[i], request, r, &classifier))
          parallel[i] = r.probability;
      }
    });
  for (auto& th : threads)
    th.join ();
  for (std::size_t i = 0; i < poses.size (); ++i)
    EXPECT_EQ (serial[i], parallel[i]) << i;

  // A classifier built with other parameters than the request's is refused, not used (it
  // answered for its own: P 0.39 read 1, found in review), by collide() and collideBatch().
  ClassifierParams other_params = request.classifier;
  other_params.C *= 0.01;
  const RobustClassifier other (other_params);
  CollisionResult r;
  EXPECT_FALSE (collide (*a, *b, poses[0], request, r, &other));
  EXPECT_EQ (r.status, CollisionResult::Status::InvalidInput);
  EXPECT_NE (r.message.find ("request.classifier"), std::string::npos) << r.message;
  std::vector<CollisionResult> batch;
  collideBatch (*a, *b, poses, request, batch, 1, &other);
  ASSERT_EQ (batch.size (), poses.size ());
  for (const CollisionResult& q : batch)
    EXPECT_EQ (q.status, CollisionResult::Status::InvalidInput);
}

// docs/RELIABILITY.md: a sensor noise far under the spacing made a 1 mm clearance a sure
// collision. A 20 cm box's surface sampled every 1 cm, 1 mm above a 30 cm plate sampled every
// 1 cm: the separator of a box edge's leaf (whose samples keep about a spacing of spread along
// their tilted normals) and the plate's tilts, and an almost exact plate sample on its wrong
// side read P = 1 (RobustClassifier, kPreciseFraction). Now the edge's spread decides: contact.
TEST (Collide, NoiseFarUnderTheSpacingDoesNotTurnAClearanceIntoACollision)
{
  pcl::PointCloud<pcl::PointXYZ> box, plate;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
      for (int k = 0; k <= 20; ++k)
        if (i == 0 || i == 20 || j == 0 || j == 20 || k == 0 || k == 20)
          box.push_back (pcl::PointXYZ (0.01f * i, 0.01f * j, 0.01f * k));
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j)
      plate.push_back (pcl::PointXYZ (0.01f * i, 0.01f * j, 0.0f));
  for (const double sigma : {1e-9, 1e-6})
  {
    CloudModelParams params;
    params.noise = SensorNoiseModel::isotropic (sigma);
    const auto a = buildCloudModel (box, params);
    const auto b = buildCloudModel (plate, params);
    for (const double gap : {0.001, 0.03})
    {
      Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity ();
      T_a_b.translation ().z () = -gap;
      const CollisionRequest request;
      CollisionResult result;
      ASSERT_TRUE (collide (*a, *b, T_a_b, request, result)) << result.message;
      expectSane (result, true, request);
      SCOPED_TRACE ("sigma " + std::to_string (sigma) + ", gap " + std::to_string (gap));
      // Before the fix: P = 1 at 1 mm for both noises. The box's own edges, about a spacing
      // uncertain along their tilted normals, keep 1 mm at contact (and 1 cm, P 0.13-0.15);
      // 3 cm is free.
      EXPECT_LT (result.probability, gap < 0.005 ? 0.9 : 0.1);
      if (gap < 0.005)
      {
        EXPECT_GT (result.probability, 0.1);
      }
    }
  }
}

// Without per-point values the traversal skips pairs whose reach weight cannot beat the maximum
// so far (issue #8): the answer must be the one of the full traversal, with fewer fits.
TEST (Collide, SkippingDominatedPairsKeepsProbabilityAndWitness)
{
  const CloudModel a (randomSheet (600, 0.2, 0.0, 0.002, 31));
  std::size_t fewer = 0;
  for (const double gap : {0.03, 0.008, 0.004, 0.0})
  {
    SCOPED_TRACE (gap);
    const CloudModel b (randomSheet (600, 0.2, gap, 0.002, 32));
    for (const double tilt : {0.0, 0.2})
    {
      const Eigen::Isometry3d T (Eigen::AngleAxisd (tilt, Eigen::Vector3d::UnitX ()));
      CollisionRequest full, lean;
      full.per_point = true;  // every reachable leaf pair
      lean.per_point = false;
      CollisionResult rf, rl;
      ASSERT_TRUE (collide (a, b, T, full, rf)) << rf.message;
      ASSERT_TRUE (collide (a, b, T, lean, rl)) << rl.message;
      EXPECT_EQ (rf.probability, rl.probability);
      EXPECT_EQ (rf.verdict, rl.verdict);
      EXPECT_EQ (rf.witness_side, rl.witness_side);
      EXPECT_EQ (rf.witness_index, rl.witness_index);
      EXPECT_LE (rl.leaf_pairs_tested, rf.leaf_pairs_tested);
      fewer += rl.leaf_pairs_tested < rf.leaf_pairs_tested;
    }
  }
  EXPECT_GT (fewer, 0u) << "no query was cheaper without per-point values";
}

// CollisionRequest::max_leaf_fits: at most that many fits, flagged when pairs were left, P a lower
// bound of the uncapped P; a cap the query never reaches changes nothing.
TEST (Collide, LeafFitCapBoundsTheWorkAndGivesALowerBound)
{
  const CloudModel a (randomSheet (600, 0.2, 0.0, 0.004, 51));
  std::size_t capped_queries = 0;
  for (const double gap : {0.02, 0.006, 0.0})
  {
    SCOPED_TRACE (gap);
    const CloudModel b (randomSheet (600, 0.2, gap, 0.004, 52));
    CollisionRequest plain;
    CollisionResult rp;
    ASSERT_TRUE (collide (a, b, Eigen::Isometry3d::Identity (), plain, rp)) << rp.message;
    EXPECT_FALSE (rp.budget_exhausted);
    if (rp.leaf_pairs_tested < 2)
      continue;  // decided by its first fit (a collision met first): nothing to cap
    for (const std::size_t cap : {std::size_t (1), rp.leaf_pairs_tested / 2, rp.leaf_pairs_tested})
    {
      SCOPED_TRACE (cap);
      CollisionRequest capped = plain;
      capped.max_leaf_fits = cap;
      CollisionResult rc;
      ASSERT_TRUE (collide (a, b, Eigen::Isometry3d::Identity (), capped, rc)) << rc.message;
      expectSane (rc, true, capped);
      EXPECT_LE (rc.leaf_pairs_tested, cap);
      EXPECT_LE (rc.probability, rp.probability);
      if (cap == rp.leaf_pairs_tested)
      {
        EXPECT_FALSE (rc.budget_exhausted);
        EXPECT_EQ (rc.probability, rp.probability);
      }
      else
      {
        EXPECT_TRUE (rc.budget_exhausted);
        EXPECT_TRUE (rc.lower_bound);
        ++capped_queries;
      }
    }
  }
  EXPECT_GT (capped_queries, 0u) << "no query reached its cap: the test would prove nothing";
}

// CollisionRequest::defer_kernel_fits: the same P whenever the query does not stop early, the
// same verdict always, fewer kernel fits; ignored with per-point values.
TEST (Collide, DeferredKernelFitsKeepTheAnswer)
{
  const CloudModel a (randomSheet (600, 0.2, 0.0, 0.002, 41));
  const CloudModel b (randomSheet (600, 0.2, 0.0, 0.002, 42));
  std::size_t kernel_default = 0, kernel_deferred = 0;
  for (const double tilt : {0.0, 0.15, 0.4})
    for (const double lift : {0.004, 0.0, -0.01})
    {
      SCOPED_TRACE (::testing::Message () << "tilt " << tilt << " lift " << lift);
      const Eigen::Isometry3d T = Eigen::Translation3d (0.0, 0.0, lift) * Eigen::AngleAxisd (tilt, Eigen::Vector3d::UnitX ());
      for (const bool exhaustive : {true, false})
      {
        CollisionRequest plain, deferring;
        plain.exhaustive = deferring.exhaustive = exhaustive;
        deferring.defer_kernel_fits = true;
        CollisionResult rp, rd;
        ASSERT_TRUE (collide (a, b, T, plain, rp)) << rp.message;
        ASSERT_TRUE (collide (a, b, T, deferring, rd)) << rd.message;
        EXPECT_EQ (rp.verdict, rd.verdict);
        if (!rp.lower_bound && !rd.lower_bound)
        {
          EXPECT_EQ (rp.probability, rd.probability);
          EXPECT_EQ (rp.witness_index, rd.witness_index);
        }
        else
          EXPECT_GT (rd.probability, plain.collision_above);
        if (exhaustive)
        {
          kernel_default += rp.kernel_leaf_pairs;
          kernel_deferred += rd.kernel_leaf_pairs;
        }
        // Per-point values need every pair's final fit: the option is ignored.
        plain.per_point = deferring.per_point = true;
        ASSERT_TRUE (collide (a, b, T, plain, rp)) << rp.message;
        ASSERT_TRUE (collide (a, b, T, deferring, rd)) << rd.message;
        EXPECT_EQ (rp.probability, rd.probability);
        ASSERT_EQ (rp.probabilities_a.size (), rd.probabilities_a.size ());
        for (std::size_t i = 0; i < rp.probabilities_a.size (); ++i)
        {
          const float p_plain = rp.probabilities_a[i], p_deferring = rd.probabilities_a[i];
          EXPECT_TRUE (p_plain == p_deferring || (std::isnan (p_plain) && std::isnan (p_deferring))) << i;
        }
        EXPECT_EQ (rp.kernel_leaf_pairs, rd.kernel_leaf_pairs);
      }
    }
  EXPECT_GT (kernel_default, 0u) << "no scene needed a kernel rung: the test would prove nothing";
  EXPECT_LE (kernel_deferred, kernel_default);
}

// ---------------------------------------------------------------------------------------------
// collide() under numerical stress and concurrency (issue #7, docs/RELIABILITY.md)

// The core in double: collide() on hierarchies of noisy sheets, then the same sheets moved by 1e5.
// ---------------------------------------------------------------------------------------------
// CollisionRequest::distance: the nearest samples' distance beyond reach

namespace
{
/** \brief The nearest pair of a and b mapped by T, by brute force: the oracle. */
struct BrutePair
{
  double distance = std::numeric_limits<double>::infinity ();
  std::size_t i = 0, j = 0;
};
BrutePair
bruteNearest (const UncertainCloud& a, const UncertainCloud& b, const Eigen::Isometry3d& T)
{
  BrutePair best;
  for (std::size_t j = 0; j < b.size (); ++j)
  {
    const Eigen::Vector3d q = T * b.means[j];
    for (std::size_t i = 0; i < a.size (); ++i)
    {
      const double d = (a.means[i] - q).norm ();
      if (d < best.distance)
        best = {d, i, j};
    }
  }
  return best;
}
/** \brief The distance from point i of c to its nearest distinct other point. */
double
nearestNeighbour (const UncertainCloud& c, std::size_t i)
{
  double best = std::numeric_limits<double>::infinity ();
  for (std::size_t k = 0; k < c.size (); ++k)
  {
    const double d = (c.means[k] - c.means[i]).norm ();
    if (d > 0.0)
      best = std::min (best, d);
  }
  return best;
}
} // namespace

TEST (CollideDistance, BeyondReachTheNearestSamplesAreFoundExactlyWithTheirDeviation)
{
  // Three shapes against each other at random rotations, their centres 2.5 to 5 object sizes apart: the
  // best-first descent must find the brute-force pair whatever the boxes' orientations.
  const Shape shapes[] = {Shape::Box, Shape::Sphere, Shape::NoisyPlane};
  CollisionRequest rq;
  rq.distance = true;
  std::mt19937 rng (31);
  std::uniform_real_distribution<double> unit (-1.0, 1.0), length (2.5, 5.0);
  int checked = 0;
  for (const Shape sa : shapes)
    for (const Shape sb : shapes)
    {
      const UncertainCloud ca = shapeCloud (sa, 500, 40 + static_cast<int> (sa));
      const UncertainCloud cb = shapeCloud (sb, 700, 50 + static_cast<int> (sb));
      const CloudModel a (ca), b (cb);
      for (int k = 0; k < 12; ++k)
      {
        Eigen::Isometry3d T = randomAxisAnglePose (rng, 0.0);
        const Eigen::Vector3d direction = Eigen::Vector3d (unit (rng), unit (rng), unit (rng)).normalized ();
        T.translation () = length (rng) * direction;
        SCOPED_TRACE (std::string (shapeName (sa)) + " against " + shapeName (sb) + ", pose " + std::to_string (k));
        CollisionResult r;
        ASSERT_TRUE (collide (a, b, T, rq, r)) << r.message;
        ASSERT_TRUE (r.no_leaf_tested);  // beyond reach: the distance comes from the samples
        ASSERT_TRUE (r.sample_distance);
        const BrutePair oracle = bruteNearest (ca, cb, T);
        EXPECT_NEAR (r.signed_distance, oracle.distance, 1e-12);
        EXPECT_LT ((r.nearest_point_a - ca.means[oracle.i]).norm (), 1e-12);
        EXPECT_LT ((r.nearest_point_b - T * cb.means[oracle.j]).norm (), 1e-12);
        // Both samples' covariances along the line between them (stored in single precision),
        // plus 0.29 of each one's spacing, its nearest distinct neighbour in its leaf: at least
        // its nearest neighbour in the whole cloud (exact on a grid: the next test).
        const Eigen::Vector3d u = (ca.means[oracle.i] - T * cb.means[oracle.j]).normalized ();
        const double variance = u.dot (ca.covariances[oracle.i] * u) +
                                u.dot (T.linear () * cb.covariances[oracle.j] * T.linear ().transpose () * u);
        const double spacings = std::pow (nearestNeighbour (ca, oracle.i), 2) + std::pow (nearestNeighbour (cb, oracle.j), 2);
        EXPECT_GE (r.signed_distance_std * r.signed_distance_std, (1.0 - 1e-6) * (variance + spacings / 12.0));
        EXPECT_LT (r.signed_distance_std, 0.1);  // a spacing within a leaf of a unit-sized object
        EXPECT_EQ (r.verdict, Verdict::Free);
        ++checked;
      }
    }
  EXPECT_EQ (checked, 108);
}

TEST (CollideDistance, OnExactGridsTheDeviationIsTheDiscretisationTerm)
{
  // Two exact grids of spacing h, 0.3 apart: the distance is 0.3 and, with no noise, the
  // deviation is the discretisation term alone, 1 / sqrt(12) of the spacing a side.
  const double h = 0.01;
  const UncertainCloud grid = jitteredGrid (20, h, 0.0, 1);
  const CloudModel a (grid), b (grid);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.translation () = Eigen::Vector3d (0.003, -0.002, 0.3);
  CollisionRequest rq;
  rq.distance = true;
  CollisionResult r;
  ASSERT_TRUE (collide (a, b, T, rq, r)) << r.message;
  ASSERT_TRUE (r.sample_distance);
  EXPECT_NEAR (r.signed_distance, std::sqrt (0.3 * 0.3 + 0.003 * 0.003 + 0.002 * 0.002), 1e-12);
  EXPECT_NEAR (r.signed_distance_std, std::sqrt (2.0 / 12.0) * h, 1e-6 * h);  // 0.288675, six digits
}

TEST (CollideDistance, OnlyBeyondReachAndOnlyWhenAsked)
{
  const UncertainCloud ca = randomSheet (400, 0.2, 0.0, 0.002, 12);
  const UncertainCloud cb = randomSheet (400, 0.2, 0.0, 0.002, 13);
  const CloudModel a (ca), b (cb);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity ();
  far.translation () = Eigen::Vector3d (0.0, 0.0, 0.5);
  CollisionRequest rq;
  CollisionResult r;
  // Not asked: no distance, as before.
  ASSERT_TRUE (collide (a, b, far, rq, r)) << r.message;
  EXPECT_TRUE (r.no_leaf_tested);
  EXPECT_FALSE (r.sample_distance);
  EXPECT_TRUE (std::isnan (r.signed_distance));
  EXPECT_TRUE (r.nearest_point_a.array ().isNaN ().all ());
  // Asked, 0.5 apart: the two sheets' nearest samples, a little under 0.5 + noise.
  rq.distance = true;
  ASSERT_TRUE (collide (a, b, far, rq, r)) << r.message;
  EXPECT_TRUE (r.sample_distance);
  EXPECT_NEAR (r.signed_distance, bruteNearest (ca, cb, far).distance, 1e-12);
  EXPECT_NEAR (r.signed_distance, 0.5, 0.02);
  // The noise of both (2 mm each) and the sheets' spacing (400 samples on 0.2 x 0.2: about 10 mm).
  EXPECT_GT (r.signed_distance_std, std::sqrt (2.0) * 0.002);
  EXPECT_LT (r.signed_distance_std, std::sqrt (2.0) * std::hypot (0.002, 0.29 * 0.03));
  // Near contact the query reaches leaf pairs: the separators give no distance, and none is
  // made up from the samples (interleaved samples of two crossing sheets are a spacing apart).
  ASSERT_TRUE (collide (a, b, Eigen::Isometry3d::Identity (), rq, r)) << r.message;
  EXPECT_FALSE (r.no_leaf_tested);
  EXPECT_FALSE (r.sample_distance);
  EXPECT_TRUE (std::isnan (r.signed_distance));
}

// Clouds of a leaf each: the separators' weighted traversal fits their one leaf pair at any
// separation, so no distance was ever given beyond reach (a probe, 2026-12-04: clouds under
// about 20 points). Their free answer is beyond reach where no leaf pair lies within the surface
// layer's reach (detail::withinReach), and the nearest samples' distance is given there.
TEST (CollideDistance, CloudsOfOneLeafGetADistanceBeyondReach)
{
  const UncertainCloud ca = randomSheet (10, 0.05, 0.0, 0.002, 21);
  const UncertainCloud cb = randomSheet (12, 0.05, 0.0, 0.002, 22);
  const CloudModel a (ca), b (cb);
  ASSERT_EQ (a.hierarchy ().nodes ().size (), 1u);
  ASSERT_EQ (b.hierarchy ().nodes ().size (), 1u);
  CollisionRequest rq;
  rq.distance = true;
  for (const double z : {0.1, 0.5, 3.0})
  {
    SCOPED_TRACE ("apart by " + std::to_string (z));
    Eigen::Isometry3d far = Eigen::Isometry3d::Identity ();
    far.translation () = Eigen::Vector3d (0.0, 0.0, z);
    CollisionResult r;
    ASSERT_TRUE (collide (a, b, far, rq, r)) << r.message;
    EXPECT_FALSE (r.no_leaf_tested);  // the one leaf pair, fitted
    EXPECT_EQ (r.verdict, Verdict::Free);
    EXPECT_TRUE (r.sample_distance);
    EXPECT_NEAR (r.signed_distance, bruteNearest (ca, cb, far).distance, 1e-12);
    EXPECT_GT (r.signed_distance_std, std::sqrt (2.0) * 0.002 * (1.0 - 1e-6));
  }
  // Within reach (the sheets 3 mm apart, within three deviations): none, as for larger clouds.
  Eigen::Isometry3d near = Eigen::Isometry3d::Identity ();
  near.translation () = Eigen::Vector3d (0.0, 0.0, 0.003);
  CollisionResult r;
  ASSERT_TRUE (collide (a, b, near, rq, r)) << r.message;
  EXPECT_FALSE (r.sample_distance);
  EXPECT_TRUE (std::isnan (r.signed_distance));
}

TEST (CollideDistance, FarFromTheOriginTheDistanceKeepsItsPrecision)
{
  const Eigen::Vector3d offset (1e5, 1e5, -1e5);
  CollisionRequest rq;
  rq.distance = true;
  const CloudModel a0 (randomSheet (400, 0.2, 0.0, 0.002, 12));
  const CloudModel b0 (randomSheet (400, 0.2, 0.03, 0.002, 13));
  const CloudModel a1 (randomSheet (400, 0.2, 0.0, 0.002, 12, offset));
  const CloudModel b1 (randomSheet (400, 0.2, 0.03, 0.002, 13, offset));
  CollisionResult r0, r1;
  ASSERT_TRUE (collide (a0, b0, Eigen::Isometry3d::Identity (), rq, r0)) << r0.message;
  ASSERT_TRUE (collide (a1, b1, Eigen::Isometry3d::Identity (), rq, r1)) << r1.message;
  ASSERT_TRUE (r0.sample_distance);
  ASSERT_TRUE (r1.sample_distance);
  EXPECT_NEAR (r0.signed_distance, r1.signed_distance, 1e-9);
  EXPECT_LT ((r1.nearest_point_a - offset - r0.nearest_point_a).norm (), 1e-9);
}

TEST (CollideDistance, ProbabilisticCollisionGivesTheNearestPointsInTheTargetFrame)
{
  ProbabilisticCollision<pcl::PointXYZ> pc;
  setPatches (pc);
  CollisionRequest rq = pc.getRequest ();
  rq.distance = true;
  pc.setRequest (rq);
  Eigen::Isometry3d T_target_input = Eigen::Isometry3d::Identity ();
  T_target_input.translation () = Eigen::Vector3d (0.05, -0.02, 0.3);
  T_target_input.rotate (Eigen::AngleAxisd (0.4, Eigen::Vector3d (1.0, 2.0, 0.5).normalized ()));
  CollisionResult r;
  ASSERT_TRUE (pc.compute (T_target_input, r)) << r.message;
  ASSERT_TRUE (r.sample_distance);
  EXPECT_NEAR ((r.nearest_point_a - r.nearest_point_b).norm (), r.signed_distance, 1e-12);
  // B's point is a target sample as it lies (the target's frame is the query frame), A's one
  // the input's sample moved by the pose: none nearer between the two models' samples.
  const auto input = pc.getInputModel ();
  const auto target = pc.getTargetModel ();
  double nearest = std::numeric_limits<double>::infinity ();
  double target_match = std::numeric_limits<double>::infinity ();
  for (const Eigen::Vector3d& q : target->hierarchy ().means ())
  {
    const Eigen::Vector3d qt = q + target->origin ();
    target_match = std::min (target_match, (qt - r.nearest_point_b).norm ());
    for (const Eigen::Vector3d& p : input->hierarchy ().means ())
      nearest = std::min (nearest, (T_target_input * (p + input->origin ()) - qt).norm ());
  }
  EXPECT_LT (target_match, 1e-9);
  EXPECT_NEAR (r.signed_distance, nearest, 1e-9);
}

TEST (CollideReliability, CollideIsStableUnderATranslationBy1e5)
{
  const Eigen::Vector3d offset (1e5, 1e5, -1e5);
  CollisionRequest rq;
  rq.exhaustive = true;
  for (const double gap : {0.02, 0.003, 0.0})
  {
    SCOPED_TRACE (gap);
    const CloudModel a0 (randomSheet (400, 0.2, 0.0, 0.002, 12));
    const CloudModel b0 (randomSheet (400, 0.2, gap, 0.002, 13));
    const CloudModel a1 (randomSheet (400, 0.2, 0.0, 0.002, 12, offset));
    const CloudModel b1 (randomSheet (400, 0.2, gap, 0.002, 13, offset));
    CollisionResult r0, r1;
    ASSERT_TRUE (collide (a0, b0, Eigen::Isometry3d::Identity (), rq, r0)) << r0.message;
    ASSERT_TRUE (collide (a1, b1, Eigen::Isometry3d::Identity (), rq, r1)) << r1.message;
    expectSane (r0, true, rq);
    expectSane (r1, true, rq);
    EXPECT_NEAR (r0.probability, r1.probability, 1e-6);
    EXPECT_EQ (r0.verdict, r1.verdict);
  }
}

TEST (CollideReliability, ConcurrentQueriesOnSharedHierarchiesMatchSerialExactly)
{
  const CloudModel a (randomSheet (600, 0.2, 0.0, 0.002, 24));
  const CloudModel b (randomSheet (600, 0.2, 0.0, 0.002, 25));
  for (const TraversalMode mode : {TraversalMode::ExpectedWeight, TraversalMode::Stochastic, TraversalMode::ExpandedBV})
  {
    CollisionRequest rq;
    rq.traversal = mode;
    rq.exhaustive = true;
    rq.per_point = true;
    const RobustClassifier classifier (rq.classifier);
    std::mt19937 rng (26);
    std::uniform_real_distribution<double> u (-1.0, 1.0);
    std::vector<Eigen::Isometry3d> poses;
    for (int i = 0; i < kConcurrentPoses; ++i)
    {
      const Eigen::Vector3d t = draw3 (u, rng).cwiseProduct (Eigen::Vector3d (0.05, 0.05, 0.01));
      const double angle = 0.3 * u (rng);
      const double ax = u (rng);
      const Eigen::Vector3d axis (ax, u (rng), 1.0);
      poses.push_back (Eigen::Translation3d (t) * Eigen::AngleAxisd (angle, axis.normalized ()));
    }
    std::vector<CollisionResult> serial (poses.size ()), parallel (poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
      ASSERT_TRUE (collide (a, b, poses[i], rq, serial[i], &classifier)) << serial[i].message;
    const int threads = 8;
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back ([&, t] () {
        for (std::size_t i = t; i < poses.size (); i += threads)
          collide (a, b, poses[i], rq, parallel[i], &classifier);
      });
    for (auto& th : pool)
      th.join ();
    for (std::size_t i = 0; i < poses.size (); ++i)
    {
      expectSane (parallel[i], true, rq);
      EXPECT_EQ (serial[i].probability, parallel[i].probability) << i;
      EXPECT_EQ (serial[i].verdict, parallel[i].verdict) << i;
      EXPECT_EQ (serial[i].witness_index, parallel[i].witness_index) << i;
      EXPECT_EQ (serial[i].leaf_pairs_tested, parallel[i].leaf_pairs_tested) << i;
      EXPECT_EQ (serial[i].bv_tests, parallel[i].bv_tests) << i;
      ASSERT_EQ (serial[i].probabilities_a.size (), parallel[i].probabilities_a.size ());
      for (std::size_t k = 0; k < serial[i].probabilities_a.size (); ++k)
      {
        const float s = serial[i].probabilities_a[k], p = parallel[i].probabilities_a[k];
        EXPECT_TRUE ((std::isnan (s) && std::isnan (p)) || s == p) << i << " " << k;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// collideBatch() (issue #8): every pose answered exactly as the single query does, whatever the
// thread count

TEST (CollideBatch, ConcurrentBatchEqualsSingleQueriesForEveryModeAndThreadCount)
{
  const CloudModel a (jitteredGrid (20, 0.005, 0.001, 1));
  const CloudModel b (jitteredGrid (24, 0.005, 0.001, 2));
  const std::vector<Eigen::Isometry3d> poses = poseSweep (kPoses, 3);
  for (const TraversalMode mode : {TraversalMode::ExpectedWeight, TraversalMode::Stochastic, TraversalMode::ExpandedBV})
  {
    CollisionRequest request;
    request.traversal = mode;
    request.seed = 77;
    request.exhaustive = true;
    request.per_point = true;
    // The reference: one collide() per pose, each drawing its own classifier.
    std::vector<CollisionResult> single (poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
      ASSERT_TRUE (collide (a, b, poses[i], request, single[i])) << single[i].message;
    const std::vector<int> counts = verdictCounts (single);
    EXPECT_GT (counts[static_cast<int> (Verdict::Free)], 0);
    EXPECT_GT (counts[static_cast<int> (Verdict::InContact)] + counts[static_cast<int> (Verdict::InCollision)], 0);
    for (const int threads : {1, 2, 3})
    {
      std::vector<CollisionResult> batch;
      EXPECT_TRUE (collideBatch (a, b, poses, request, batch, threads));
      ASSERT_EQ (batch.size (), poses.size ());
      for (std::size_t i = 0; i < poses.size (); ++i)
      {
        ASSERT_EQ (batch[i].probabilities_a.size (), a.size ());
        expectSameResult (single[i], batch[i],
                          "mode " + std::to_string (static_cast<int> (mode)) + ", threads " + std::to_string (threads) +
                              ", pose " + std::to_string (i));
      }
    }
  }
}

TEST (CollideBatch, ConcurrentBatchWithBadPosesFailsThemAndAnswersTheOthers)
{
  const CloudModel a (jitteredGrid (16, 0.005, 0.001, 4));
  const CloudModel b (jitteredGrid (16, 0.005, 0.001, 5));
  std::vector<Eigen::Isometry3d> poses = poseSweep (8, 6);
  poses[2].translation ().y () = std::numeric_limits<double>::quiet_NaN ();
  poses[5].linear () *= 1.5;
  CollisionRequest request;
  request.per_point = true;
  const RobustClassifier classifier (request.classifier);
  std::vector<CollisionResult> batch (3);  // stale content is replaced
  EXPECT_FALSE (collideBatch (a, b, poses, request, batch, 2, &classifier));
  ASSERT_EQ (batch.size (), poses.size ());
  for (std::size_t i = 0; i < poses.size (); ++i)
  {
    CollisionResult single;
    const bool ok = collide (a, b, poses[i], request, single, &classifier);
    EXPECT_EQ (ok, i != 2 && i != 5) << i;
    if (!ok)
    {
      EXPECT_EQ (batch[i].status, CollisionResult::Status::InvalidInput) << i;
      EXPECT_NE (batch[i].message.find ("pose"), std::string::npos) << batch[i].message;
      EXPECT_TRUE (std::isnan (batch[i].probability)) << i;
      EXPECT_EQ (batch[i].verdict, Verdict::Unknown) << i;
    }
    else
    {
      EXPECT_TRUE (batch[i].ok ()) << i << ": " << batch[i].message;
    }
    expectSameResult (single, batch[i], "pose " + std::to_string (i));
  }
}

TEST (CollideBatch, NegativeThreadCountThrowsNamingIt)
{
  const CloudModel a (jitteredGrid (4, 0.01, 0.001, 7));
  const std::vector<Eigen::Isometry3d> poses (2, Eigen::Isometry3d::Identity ());
  std::vector<CollisionResult> results;
  try
  {
    collideBatch (a, a, poses, CollisionRequest (), results, -1);
    FAIL () << "threads = -1 accepted";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("threads"), std::string::npos) << what;
    EXPECT_NE (what.find ("-1"), std::string::npos) << what;
  }
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (patchWithHole (4, 0.01, Eigen::Vector3d::Zero (), 8));
  pc.setTargetCloud (patchWithHole (4, 0.01, Eigen::Vector3d::Zero (), 9));
  try
  {
    pc.computeBatch (poses, results, -3);
    FAIL () << "threads = -3 accepted";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("threads = -3"), std::string::npos) << what;
  }
}

TEST (CollideBatch, EmptyPoseListGivesNoResults)
{
  const CloudModel a (jitteredGrid (4, 0.01, 0.001, 10));
  std::vector<CollisionResult> results (5);
  EXPECT_TRUE (collideBatch (a, a, {}, CollisionRequest (), results));
  EXPECT_TRUE (results.empty ());
  ProbabilisticCollision<pcl::PointXYZ> pc;  // no clouds: nothing to answer, nothing fails
  results.resize (2);
  EXPECT_TRUE (pc.computeBatch ({}, results, 2));
  EXPECT_TRUE (results.empty ());
}

TEST (CollideBatch, InvalidRequestOrPoseFailsEveryPoseLikeCollide)
{
  const CloudModel a (jitteredGrid (6, 0.01, 0.001, 11));
  std::vector<Eigen::Isometry3d> poses = poseSweep (4, 12);
  CollisionRequest bad;
  bad.rho_min = 2.0;
  for (const bool bad_pose : {false, true})
  {
    const CollisionRequest& request = bad_pose ? CollisionRequest () : bad;
    if (bad_pose)
      for (Eigen::Isometry3d& T : poses)
        T.linear () *= 2.0;  // a scale, not a rotation
    const CloudModel& b = a;
    std::vector<CollisionResult> batch;
    EXPECT_FALSE (collideBatch (a, b, poses, request, batch, 2));
    ASSERT_EQ (batch.size (), poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
    {
      CollisionResult single;
      EXPECT_FALSE (collide (a, b, poses[i], request, single));
      EXPECT_FALSE (batch[i].message.empty ());
      expectSameResult (single, batch[i], "pose " + std::to_string (i));
    }
  }
}

// The overload with `ready` (pcd_collision -poses prints through it): every pose handed over once,
// in pose order, each as the batch without it answers it, whatever the thread count; a failed pose
// in its place; the batch's verdict counted before ready clears the results.
TEST (CollideBatch, StreamedAnswersComeInPoseOrderAsTheBatchGivesThem)
{
  const CloudModel a (jitteredGrid (20, 0.005, 0.001, 1));
  const CloudModel b (jitteredGrid (24, 0.005, 0.001, 2));
  std::vector<Eigen::Isometry3d> poses = poseSweep (kPoses, 3);
  CollisionRequest request;
  request.per_point = true;
  const RobustClassifier classifier (request.classifier);
  std::vector<CollisionResult> want;
  ASSERT_TRUE (collideBatch (a, b, poses, request, want, 1, &classifier));
  const std::vector<int> counts = verdictCounts (want);
  EXPECT_GT (counts[static_cast<int> (Verdict::Free)], 0);
  EXPECT_GT (counts[static_cast<int> (Verdict::InContact)] + counts[static_cast<int> (Verdict::InCollision)], 0);
  for (const bool bad_pose : {false, true})
  {
    if (bad_pose)
      poses[1].translation ().x () = std::numeric_limits<double>::quiet_NaN ();
    for (const int threads : {1, 2, 3})
    {
      std::vector<std::size_t> order;
      std::vector<CollisionResult> got (poses.size ()), results;
      const bool ok = collideBatch (a, b, poses, request, results, threads, &classifier, [&] (std::size_t i) {
        order.push_back (i);
        got[i] = std::move (results[i]);
        results[i] = CollisionResult ();  // what a caller that prints each answer does
      });
      const std::string where = "threads " + std::to_string (threads) + (bad_pose ? ", a bad pose" : "");
      EXPECT_EQ (ok, !bad_pose) << where;
      ASSERT_EQ (order.size (), poses.size ()) << where;
      for (std::size_t i = 0; i < poses.size (); ++i)
      {
        EXPECT_EQ (order[i], i) << where;
        if (bad_pose && i == 1)
        {
          EXPECT_EQ (got[i].status, CollisionResult::Status::InvalidInput) << where;
          continue;
        }
        expectSameResult (want[i], got[i], where + ", pose " + std::to_string (i));
      }
    }
  }
}

TEST (CollideBatch, AnExceptionFromReadyStopsTheBatchAndIsRethrown)
{
  const CloudModel a (jitteredGrid (12, 0.005, 0.001, 4));
  const CloudModel b (jitteredGrid (12, 0.005, 0.001, 5));
  const std::vector<Eigen::Isometry3d> poses = poseSweep (kPoses, 6);
  struct Stop
  {
    std::size_t pose;
  };
  for (const int threads : {1, 2})
  {
    std::vector<std::size_t> order;
    std::vector<CollisionResult> results;
    try
    {
      collideBatch (a, b, poses, CollisionRequest (), results, threads, nullptr, [&] (std::size_t i) {
        order.push_back (i);
        if (i == 3)
          throw Stop{i};
      });
      FAIL () << "threads " << threads << ": the exception from ready was lost";
    }
    catch (const Stop& stop)
    {
      EXPECT_EQ (stop.pose, 3u);
    }
    EXPECT_EQ (order, (std::vector<std::size_t>{0, 1, 2, 3})) << "threads " << threads;
  }
  // An empty ready is the batch without it.
  std::vector<CollisionResult> plain, streamed;
  ASSERT_TRUE (collideBatch (a, b, poses, CollisionRequest (), plain, 2));
  ASSERT_TRUE (collideBatch (a, b, poses, CollisionRequest (), streamed, 2, nullptr, {}));
  ASSERT_EQ (streamed.size (), plain.size ());
  for (std::size_t i = 0; i < plain.size (); ++i)
    expectSameResult (plain[i], streamed[i], "pose " + std::to_string (i));
}

// ---------------------------------------------------------------------------------------------
// verdictFor()

TEST (VerdictFor, ThresholdsAreStrictSoTheBoundariesReadContact)
{
  // collision_request.h: P < free_below is Free, P > collision_above InCollision, and
  // free_below <= P <= collision_above InContact (both boundaries included in contact).
  const double nan = std::numeric_limits<double>::quiet_NaN ();
  struct Case
  {
    double free_below, collision_above, p;
    Verdict expected;
  };
  const Case cases[] = {
      {0.1, 0.9, nan, Verdict::Unknown},
      {0.1, 0.9, 0.0, Verdict::Free},
      {0.1, 0.9, std::nextafter (0.1, 0.0), Verdict::Free},
      {0.1, 0.9, 0.1, Verdict::InContact},
      {0.1, 0.9, 0.5, Verdict::InContact},
      {0.1, 0.9, 0.9, Verdict::InContact},
      {0.1, 0.9, std::nextafter (0.9, 1.0), Verdict::InCollision},
      {0.1, 0.9, 1.0, Verdict::InCollision},
      // Other thresholds move the boundaries with them.
      {0.2, 0.6, nan, Verdict::Unknown},
      {0.2, 0.6, 0.15, Verdict::Free},
      {0.2, 0.6, 0.2, Verdict::InContact},
      {0.2, 0.6, 0.6, Verdict::InContact},
      {0.2, 0.6, 0.65, Verdict::InCollision},
      // Near the range ends every verdict is still reached: P = 0 is free, P = 1 collision.
      {1e-12, 1.0 - 1e-12, 0.0, Verdict::Free},
      {1e-12, 1.0 - 1e-12, 1e-12, Verdict::InContact},
      {1e-12, 1.0 - 1e-12, 1.0, Verdict::InCollision},
      // A single threshold: only P = 0.5 itself is contact.
      {0.5, 0.5, std::nextafter (0.5, 0.0), Verdict::Free},
      {0.5, 0.5, 0.5, Verdict::InContact},
      {0.5, 0.5, std::nextafter (0.5, 1.0), Verdict::InCollision},
  };
  for (const Case& c : cases)
  {
    CollisionRequest request;
    request.free_below = c.free_below;
    request.collision_above = c.collision_above;
    ASSERT_NO_THROW (request.validate ());
    EXPECT_EQ (verdictFor (c.p, request), c.expected)
        << "P = " << c.p << " with free_below " << c.free_below << ", collision_above " << c.collision_above
        << ": got " << verdictName (verdictFor (c.p, request)) << ", expected " << verdictName (c.expected);
  }
}

TEST (VerdictFor, DefaultRequestGivesTheDocumentedBands)
{
  const CollisionRequest request;  // free below 0.1, collision above 0.9
  EXPECT_EQ (verdictFor (0.05, request), Verdict::Free);
  EXPECT_EQ (verdictFor (0.1, request), Verdict::InContact);
  EXPECT_EQ (verdictFor (0.9, request), Verdict::InContact);
  EXPECT_EQ (verdictFor (0.95, request), Verdict::InCollision);
  EXPECT_EQ (verdictFor (-std::numeric_limits<double>::quiet_NaN (), request), Verdict::Unknown);
}

// verdictFor took any P: 1.5 read collision, -0.1 free (a probe, 2026-12-04). A probability
// outside [0, 1] (or infinite) is refused naming it; NaN is "not computed" and stays Unknown.
TEST (VerdictFor, AProbabilityOutsideZeroToOneIsRefusedByName)
{
  const CollisionRequest request;
  for (const double p : {1.5, -0.1, std::nextafter (1.0, 2.0), -std::numeric_limits<double>::denorm_min (),
                         std::numeric_limits<double>::infinity (), -std::numeric_limits<double>::infinity ()})
  {
    try
    {
      const Verdict v = verdictFor (p, request);
      ADD_FAILURE () << "P = " << p << " read " << verdictName (v);
    }
    catch (const pcl::BadArgumentException& e)
    {
      EXPECT_NE (std::string (e.what ()).find ("[pcl_probcollision::verdictFor] probability "), std::string::npos) << e.what ();
      EXPECT_NE (std::string (e.what ()).find (" outside [0, 1]"), std::string::npos) << e.what ();
    }
  }
  EXPECT_EQ (verdictFor (std::numeric_limits<double>::quiet_NaN (), request), Verdict::Unknown);
  EXPECT_EQ (verdictFor (0.0, request), Verdict::Free);
  EXPECT_EQ (verdictFor (-0.0, request), Verdict::Free);
  EXPECT_EQ (verdictFor (1.0, request), Verdict::InCollision);
}

TEST (VerdictFor, ThresholdsOutOfRangeAreRefusedByName)
{
  CollisionRequest request;
  request.free_below = 0.6;  // above collision_above's range: every P would read free or collision
  EXPECT_THROW (
      {
        try
        {
          verdictFor (0.7, request);
        }
        catch (const pcl::BadArgumentException& e)
        {
          EXPECT_NE (std::string (e.what ()).find ("free_below 0.6"), std::string::npos) << e.what ();
          throw;
        }
      },
      pcl::BadArgumentException);
  request = CollisionRequest ();
  request.collision_above = std::numeric_limits<double>::quiet_NaN ();
  EXPECT_THROW (verdictFor (0.7, request), pcl::BadArgumentException);
}
